"""mu_eff of the dynamic tilt test against its ramp rate, and its zero-rate extrapolation.

    python benchmarks/dynamic_tilt_rate.py [--network pair] [--realizations 2000] [--steps 5]
        [--rates 1e-4 2e-4 5e-4 1e-3 2e-3 5e-3 1e-2] [--save PATH]

One run of the configuration below per rate (``[dynamics] tilt_rate``) and
one without it (the quasi-static network tilt test of the same states), the
same seed: the states at the recorded time ``--steps`` are the same in every
run (the tilt tests read a stream of their own), so the rates are paired by
realization. Prints mu_eff at each rate (mean and standard error over the
realizations), the difference from the slowest rate, and the zero-rate
extrapolations of :func:`slidernet.analysis.tilt_rate.zero_rate` (linear and
power in the rate), with the zero-rate mu_eff less the quasi-static one,
paired. ``--save``: the samples, an .npz of ``rates``, ``mu_eff`` (R, K) and ``quasi_static`` (R,).

The scene: ``--network`` ``pair`` (the paper's two sliders) or ``irregular16``
(an irregular network of 16, seed 2); mu_d = 0.5, mu_s ~ N(0.6, 0.03^2),
gaussian_steps with sigma_theta / Ntilde = 1, tau_dyn / tau_th = 1e-3.
"""

from __future__ import annotations

import argparse

import numpy as np

import slidernet
from slidernet.analysis.tilt_rate import zero_rate

NETWORKS = {"pair": {"kind": "two_slider", "Ntilde": 1e-7},
            "irregular16": {"kind": "irregular", "n": 16, "Ntilde": 1e-7, "seed": 2}}


def samples(network: str, realizations: int, steps: int, rate: float | None) -> np.ndarray:
    """mu_eff of each realization's tilt test at t = ``steps``, shape (R,)."""
    dynamics = {"tau_ratio": 1e-3, **({} if rate is None else {"tilt_rate": rate})}
    cfg = {"seed": 5, "realizations": realizations, "steps": steps, "record": [steps],
           "network": NETWORKS[network],
           "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.03}},
           "driver": {"name": "gaussian_steps", "sigma_theta": 1e-7}, "dynamics": dynamics,
           "observables": ["n", "mu_eff", "mu_eff_realization"], "mu_eff_at": "records",
           "execution": {"workers": 1}}
    ds = slidernet.run(cfg, progress=False)
    return ds["mu_eff_realization"].sel(t=steps).values


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--network", choices=sorted(NETWORKS), default="pair")
    parser.add_argument("--realizations", type=int, default=2000)
    parser.add_argument("--steps", type=int, default=5)
    parser.add_argument("--rates", type=float, nargs="+", default=[1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2])
    parser.add_argument("--save", help="an .npz file for the samples")
    args = parser.parse_args()
    rates = np.array(sorted(args.rates))
    M = np.stack([samples(args.network, args.realizations, args.steps, r) for r in rates], axis=1)
    qs = samples(args.network, args.realizations, args.steps, None)
    if args.save:
        np.savez(args.save, rates=rates, mu_eff=M, quasi_static=qs)
    sqrt_r = np.sqrt(M.shape[0])
    for k, r in enumerate(rates):
        d = M[:, k] - M[:, 0]
        print(f"rate {r:7.1e}: mu_eff {M[:, k].mean():.6f} +- {M[:, k].std(ddof=1) / sqrt_r:.6f}   "
              f"less rate {rates[0]:.0e}: {d.mean():+.2e} +- {d.std(ddof=1) / sqrt_r:.1e}")
    print(f"quasi-static  : mu_eff {qs.mean():.6f} +- {qs.std(ddof=1) / sqrt_r:.6f}")
    for model in ("linear", "power"):
        z = zero_rate(rates, M, model)
        paired = zero_rate(rates, M - qs[:, None], model)
        print(f"{model:6s}: mu_eff(0) = {z.mu_eff:.6f} +- {z.se:.6f}, slope {z.slope:+.3f}, exponent "
              f"{z.exponent:.3f} +- {z.exponent_se:.3f}; less the quasi-static: {paired.mu_eff:+.2e} +- "
              f"{paired.se:.1e}")


if __name__ == "__main__":
    main()
