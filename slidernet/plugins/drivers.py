"""Temperature drivers: the thermal dilation theta(t) = kappa (T(t) - T0).

A driver plugin is any object with ``thetas(rng, steps) -> ndarray``: the
``steps + 1`` values theta(t_q) at t_q = q tau_th, q = 0 ... steps. Between
two values theta is linear in time (the paper, section III.A), which is what
lets the solver resolve every rearrangement exactly.

Each built-in driver is a small class in the style of ``hoomd.variant``: the
constructor validates and stores its parameters (raising
:class:`~slidernet.errors.ConfigError` with a message that names the
parameter), and ``thetas`` does the work with the ``numpy.random.Generator``
it is given, and nothing else. Time is in units of tau_th and theta is the
dimensionless dilation throughout.

==========================  ==================================================
name                        theta(t_q)
==========================  ==================================================
``gaussian_steps``          independent N(0, sigma_theta^2) draws (the paper)
``ornstein_uhlenbeck``      stationary Gaussian, correlation time ``tau_c``
``sinusoidal``              a periodic cycle plus independent Gaussian noise
``ramp``                    ``theta0 + rate t``, or a triangle wave
``constant``                ``theta0`` at every t: no thermal cycling
``series``                  ``kappa (T(t0 + q tau_th) - T0)`` from a CSV file
==========================  ==================================================
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from slidernet._validation import check_scalar, is_number_text, read_real
from slidernet.errors import ConfigError, param_error
from slidernet.kernels.jit import cached_jit


class GaussianSteps:
    """The paper's driver: theta(t_q) drawn independently from N(0, sigma_theta^2).

    Parameters
    ----------
    sigma_theta : float
        Standard deviation of theta (dimensionless dilation); > 0.

    Examples
    --------
    >>> import numpy as np
    >>> GaussianSteps(sigma_theta=1e-6).thetas(np.random.default_rng(0), 4).shape
    (5,)
    >>> GaussianSteps(sigma_theta=-1e-6)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'sigma_theta' parameter of gaussian_steps must be > 0. Got -1e-06 instead.
    """

    # Parameters for slidernet.testing.check_driver and the plugin contract test.
    example_params: ClassVar[dict[str, Any]] = {"sigma_theta": 1e-6}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"sigma_theta": "1"}

    def __init__(self, sigma_theta: float) -> None:
        self.sigma_theta = check_scalar(sigma_theta, "sigma_theta", "gaussian_steps", "> 0")

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        """theta at t = 0 ... steps (in tau_th), shape ``(steps + 1,)``."""
        return self.sigma_theta * rng.standard_normal(steps + 1)

    def __repr__(self) -> str:
        return f"GaussianSteps(sigma_theta={self.sigma_theta!r})"


@cached_jit()
def _ar1_in_place(y, phi):  # pragma: no cover - compiled; tested through OrnsteinUhlenbeck
    """y[q] += phi y[q - 1] for q = 1 ... len(y) - 1, in order: the AR(1) recursion, in place."""
    for q in range(1, y.size):
        y[q] += phi * y[q - 1]


class OrnsteinUhlenbeck:
    """Correlated Gaussian theta: an Ornstein-Uhlenbeck process sampled exactly at t_q.

    theta relaxes towards ``theta0`` with correlation time ``tau_c``; its
    stationary law is N(theta0, sigma_theta^2) and its autocorrelation at lag
    q is exp(-q / tau_c). With y_q = theta(t_q) - theta0, the discretisation is
    exact (no time-step error)::

        y_0     = sigma_theta xi_0                    (drawn from the stationary law)
        y_{q+1} = y_q e^{-1/tau_c} + sigma_theta sqrt(1 - e^{-2/tau_c}) xi_{q+1}

    with xi_0 ... xi_steps independent standard normal draws. As tau_c -> 0 it
    tends to :class:`GaussianSteps`.

    Parameters
    ----------
    sigma_theta : float
        Stationary standard deviation of theta (dimensionless dilation); > 0.
    tau_c : float
        Correlation time, in units of tau_th; > 0.
    theta0 : float, optional
        Stationary mean of theta (dimensionless); default 0.

    Examples
    --------
    >>> import numpy as np
    >>> ou = OrnsteinUhlenbeck(sigma_theta=1e-6, tau_c=10.0)
    >>> theta = ou.thetas(np.random.default_rng(0), 1000)
    >>> theta.shape
    (1001,)
    >>> round(float(np.corrcoef(theta[:-1], theta[1:])[0, 1]), 1)  # about exp(-0.1) = 0.905
    0.9
    >>> OrnsteinUhlenbeck(sigma_theta=1e-6, tau_c=0)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'tau_c' parameter of ornstein_uhlenbeck must be > 0. Got 0.0 instead.
    """

    # Parameters for slidernet.testing.check_driver and the plugin contract test.
    example_params: ClassVar[dict[str, Any]] = {"sigma_theta": 1e-6, "tau_c": 2.0}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"sigma_theta": "1", "tau_c": "tau_th", "theta0": "1"}

    def __init__(self, sigma_theta: float, tau_c: float, theta0: float = 0.0) -> None:
        self.sigma_theta = check_scalar(sigma_theta, "sigma_theta", "ornstein_uhlenbeck", "> 0")
        self.tau_c = check_scalar(tau_c, "tau_c", "ornstein_uhlenbeck", "> 0")
        self.theta0 = check_scalar(theta0, "theta0", "ornstein_uhlenbeck")

    @property
    def phi(self) -> float:
        """The lag-1 autocorrelation e^{-1/tau_c}."""
        return math.exp(-1.0 / self.tau_c)

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        """theta at t = 0 ... steps (in tau_th), shape ``(steps + 1,)``.

        Uses ``steps + 1`` standard normal draws from ``rng``, in one call.
        """
        xi = rng.standard_normal(steps + 1)
        # -expm1(-2/tau_c) = 1 - e^{-2/tau_c}, accurate for a large tau_c too.
        y = self.sigma_theta * math.sqrt(-math.expm1(-2.0 / self.tau_c)) * xi
        y[0] = self.sigma_theta * xi[0]
        _ar1_in_place(y, self.phi)
        return self.theta0 + y

    def __repr__(self) -> str:
        return (f"OrnsteinUhlenbeck(sigma_theta={self.sigma_theta!r}, tau_c={self.tau_c!r}, "
                f"theta0={self.theta0!r})")


class Sinusoidal:
    """A periodic (daily) cycle plus noise: theta(t_q) = A sin(2 pi t_q / period + phase) + s xi_q + theta0.

    ``A`` is ``amplitude``, ``s`` is ``noise_std`` and the xi_q are
    independent standard normal draws. theta is sampled at the integer times
    t_q and linear in between, so a period of a few tau_th is a polygon, not
    a sine, and a period of 2 tau_th or less is aliased.

    Parameters
    ----------
    amplitude : float
        Amplitude of the cycle (dimensionless dilation); >= 0.
    period : float
        Period of the cycle, in units of tau_th; > 0.
    phase : float, optional
        Phase at t = 0, in radians; default 0.
    noise_std : float, optional
        Standard deviation of the noise added at each t_q (dimensionless
        dilation); >= 0, default 0. At least one of ``amplitude`` and
        ``noise_std`` must be > 0.
    theta0 : float, optional
        Mean of theta (dimensionless); default 0.

    Examples
    --------
    >>> import numpy as np
    >>> Sinusoidal(amplitude=2.0, period=4).thetas(np.random.default_rng(0), 4).round(12)
    array([ 0.,  2.,  0., -2.,  0.])
    >>> Sinusoidal(amplitude=0.0, period=24)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'amplitude' parameter of sinusoidal must be > 0 when noise_std = 0. ...
    """

    # Parameters for slidernet.testing.check_driver and the plugin contract test.
    example_params: ClassVar[dict[str, Any]] = {"amplitude": 1e-6, "period": 100.0}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {
        "amplitude": "1",
        "period": "tau_th",
        "phase": "rad",
        "noise_std": "1",
        "theta0": "1",
    }

    def __init__(self, amplitude: float, period: float, phase: float = 0.0, noise_std: float = 0.0,
                 theta0: float = 0.0) -> None:
        self.amplitude = check_scalar(amplitude, "amplitude", "sinusoidal", ">= 0")
        self.period = check_scalar(period, "period", "sinusoidal", "> 0")
        self.phase = check_scalar(phase, "phase", "sinusoidal")
        self.noise_std = check_scalar(noise_std, "noise_std", "sinusoidal", ">= 0")
        self.theta0 = check_scalar(theta0, "theta0", "sinusoidal")
        if self.amplitude == 0 and self.noise_std == 0:
            # theta would be constant: nothing would ever rearrange.
            raise param_error("amplitude", "sinusoidal", "> 0 when noise_std = 0", self.amplitude)

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        """theta at t = 0 ... steps (in tau_th), shape ``(steps + 1,)``.

        Uses ``steps + 1`` standard normal draws from ``rng`` when
        ``noise_std > 0``, none otherwise.
        """
        t = np.arange(steps + 1, dtype=np.float64)
        # t mod period first: the phase stays accurate at large t, and an integer
        # period gives theta(t + period) == theta(t) to the bit.
        theta = self.amplitude * np.sin(2.0 * np.pi * (np.mod(t, self.period) / self.period) + self.phase)
        if self.noise_std > 0:
            theta += self.noise_std * rng.standard_normal(steps + 1)
        return self.theta0 + theta

    def __repr__(self) -> str:
        return (f"Sinusoidal(amplitude={self.amplitude!r}, period={self.period!r}, phase={self.phase!r}, "
                f"noise_std={self.noise_std!r}, theta0={self.theta0!r})")


class Ramp:
    """A deterministic ramp theta(t) = theta0 + rate t, or a triangle wave of that slope.

    Without ``period``, theta grows (or falls) linearly for ever. With
    ``period = P``, theta goes from ``theta0`` to ``theta0 + rate P / 2`` at
    slope ``rate`` over the first half period and back at slope ``-rate``
    over the second, and so on::

        theta(t) = theta0 + rate (P/2 - |t mod P - P/2|)

    theta is sampled at the integer t_q and linear in between, so the wave is
    exact when P is an even integer; otherwise its corners are cut. The
    ``rng`` is not used.

    Parameters
    ----------
    rate : float
        Slope d theta / dt, in units of 1 / tau_th; != 0.
    theta0 : float, optional
        theta at t = 0 (dimensionless); default 0.
    period : float, optional
        Period of the triangle wave, in units of tau_th; > 0. Default none: a
        plain ramp.

    Examples
    --------
    >>> import numpy as np
    >>> Ramp(rate=0.5, theta0=1.0).thetas(np.random.default_rng(0), 4)
    array([1. , 1.5, 2. , 2.5, 3. ])
    >>> Ramp(rate=1.0, period=4).thetas(np.random.default_rng(0), 6)
    array([0., 1., 2., 1., 0., 1., 2.])
    >>> Ramp(rate=0)
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The 'rate' parameter of ramp must be != 0. Got 0.0 instead.
    """

    # Parameters for slidernet.testing.check_driver and the plugin contract test.
    example_params: ClassVar[dict[str, Any]] = {"rate": 1e-7, "period": 20.0}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"rate": "1/tau_th", "theta0": "1", "period": "tau_th"}

    def __init__(self, rate: float, theta0: float = 0.0, period: float | None = None) -> None:
        self.rate = check_scalar(rate, "rate", "ramp", "!= 0")
        self.theta0 = check_scalar(theta0, "theta0", "ramp")
        self.period = None if period is None else check_scalar(period, "period", "ramp", "> 0")

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        """theta at t = 0 ... steps (in tau_th), shape ``(steps + 1,)``; ``rng`` is unused."""
        t = np.arange(steps + 1, dtype=np.float64)
        if self.period is not None:
            half = 0.5 * self.period
            t = half - np.abs(np.mod(t, self.period) - half)
        return self.theta0 + self.rate * t

    def __repr__(self) -> str:
        return f"Ramp(rate={self.rate!r}, theta0={self.theta0!r}, period={self.period!r})"


class Constant:
    """theta(t_q) = theta0 at every t_q: no thermal cycling at all.

    The control of a study of cycling (sigma_theta / Ntilde = 0): nothing
    slips, so only what evolves without slips is seen, such as contact
    strengthening (``friction.strengthening``). The ``rng`` is not used.

    Parameters
    ----------
    theta0 : float, optional
        theta at every t (dimensionless); default 0.

    Examples
    --------
    >>> import numpy as np
    >>> Constant(theta0=2e-7).thetas(np.random.default_rng(0), 3)
    array([2.e-07, 2.e-07, 2.e-07, 2.e-07])
    """

    # Parameters for slidernet.testing.check_driver and the plugin contract test.
    example_params: ClassVar[dict[str, Any]] = {"theta0": 1e-7}

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"theta0": "1"}

    def __init__(self, theta0: float = 0.0) -> None:
        self.theta0 = check_scalar(theta0, "theta0", "constant")

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        """theta at t = 0 ... steps (in tau_th), shape ``(steps + 1,)``; ``rng`` is unused."""
        return np.full(steps + 1, self.theta0, dtype=np.float64)

    def __repr__(self) -> str:
        return f"Constant(theta0={self.theta0!r})"


def _read_series(path: Path, delimiter: str, owner: str) -> tuple[np.ndarray, np.ndarray]:
    """The (time, temperature) columns of a CSV file, checked; a header row is optional."""
    where = f"The temperature file {str(path)!r} of the {owner} driver"
    if not path.exists():
        raise ConfigError(f"{where} does not exist.")
    if not path.is_file():
        raise ConfigError(f"{where} is not a file.")
    rows: list[tuple[float, float]] = []
    header_allowed = True  # only as the first line that is not blank or a comment
    try:
        with path.open(newline="", encoding="utf-8-sig") as fh:
            reader = csv.reader(fh, delimiter=delimiter)
            for fields in reader:
                lineno = reader.line_num
                fields = [f.strip() for f in fields]
                if not any(fields) or fields[0].startswith("#"):
                    continue  # blank lines and comments
                if len(fields) != 2:
                    raise ConfigError(f"{where}: line {lineno} has {len(fields)} columns; expected 2 "
                                      f"(time, temperature) separated by {delimiter!r}.")
                line = f"{where}: line {lineno}"
                try:
                    rows.append((read_real(fields[0], "'time'", line),
                                 read_real(fields[1], "'temperature'", line)))
                except ConfigError:
                    # A header is the first line that is not two numbers, and only the first.
                    if not header_allowed or all(is_number_text(f) for f in fields):
                        raise
                header_allowed = False
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{where} cannot be read: {exc}") from None
    if len(rows) < 2:
        raise ConfigError(f"{where} has {len(rows)} data row(s); at least 2 are needed.")
    data = np.array(rows, dtype=np.float64)
    time, temperature = data[:, 0], data[:, 1]
    step = np.diff(time)
    if (step <= 0).any():
        i = int(np.argmax(step <= 0))
        raise ConfigError(f"{where}: the times must be strictly increasing; data row {i + 2} has time "
                          f"{float(time[i + 1])!r} after {float(time[i])!r}.")
    return time, temperature


class Series:
    """A recorded temperature series: theta(t_q) = kappa (T(t0 + q tau_th) - T0).

    The CSV file has two columns, time and temperature, one sample a line,
    with an optional header line; blank lines and lines starting with ``#``
    are skipped. The times must be strictly increasing but need not be evenly
    spaced: T is interpolated linearly between samples, which is also how
    the solver treats theta between two t_q. The file is read, and checked,
    once, in the constructor; the ``rng`` is not used. The format, with an
    example: ``docs/guides/file-formats.md``.

    Parameters
    ----------
    path : str or path-like
        The CSV file.
    kappa : float
        Thermal expansion coefficient, in 1 / (the file's temperature unit),
        e.g. 1/K; != 0.
    T0 : float
        Reference temperature, in the file's temperature unit (K or °C).
    tau_th : float
        The thermal time in the file's time unit: sample q of the run is read
        at time ``t0 + q tau_th``; > 0.
    t0 : float, optional
        Time of t = 0, in the file's time unit, within the series; default
        the first sample's time.
    delimiter : str, optional
        The column separator, one character; default ``","``.

    Attributes
    ----------
    time, temperature : ndarray, shape (n_samples,)
        The series as read.
    covered_steps : int
        The largest ``steps`` the series covers.

    Raises
    ------
    ConfigError
        In the constructor, if the file is missing or unreadable, has fewer
        than 2 data rows, a NaN or inf, or times that do not increase
        strictly, or if a parameter is invalid; in :meth:`thetas`, if the
        series is too short for ``steps``.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> folder = tempfile.TemporaryDirectory()
    >>> csv_file = pathlib.Path(folder.name) / "T.csv"
    >>> _ = csv_file.write_text("hour,celsius\\n0,20.0\\n2,22.0\\n4,21.0\\n")
    >>> series = Series(csv_file, kappa=0.5, T0=20.0, tau_th=1.0)
    >>> series.covered_steps
    4
    >>> series.thetas(np.random.default_rng(0), 4)
    array([0.  , 0.5 , 1.  , 0.75, 0.5 ])
    >>> series.thetas(np.random.default_rng(0), 5)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    slidernet.errors.ConfigError: The temperature file '...T.csv' of the series driver covers 4 steps ...
    >>> folder.cleanup()
    """

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {
        "path": "—",
        "kappa": "1/(the file's temperature unit)",
        "T0": "the file's temperature unit",
        "tau_th": "the file's time unit",
        "t0": "the file's time unit",
        "delimiter": "—",
    }

    def __init__(self, path: str | os.PathLike, kappa: float, T0: float, tau_th: float, t0: float | None = None,
                 delimiter: str = ",") -> None:
        if not isinstance(path, (str, os.PathLike)) or not str(path):
            raise param_error("path", "series", "a non-empty path", path)
        if not (isinstance(delimiter, str) and len(delimiter) == 1 and delimiter not in "\r\n\"#"):
            raise param_error("delimiter", "series", "one character (not a quote, '#' or a newline)", delimiter)
        self.kappa = check_scalar(kappa, "kappa", "series", "!= 0")
        self.T0 = check_scalar(T0, "T0", "series")
        self.tau_th = check_scalar(tau_th, "tau_th", "series", "> 0")
        self.path = Path(path)
        self.delimiter = delimiter
        self.time, self.temperature = _read_series(self.path, delimiter, "series")
        first, last = float(self.time[0]), float(self.time[-1])
        if t0 is None:
            self.t0 = first
        else:
            self.t0 = check_scalar(t0, "t0", "series")
            if not first <= self.t0 <= last:
                raise param_error("t0", "series", f"within the series' times [{first!r}, {last!r}]", self.t0)
        # The relative slack lets a grid that ends on the last sample count, whatever the rounding
        # of t0 + q tau_th; np.interp returns the last value there.
        self.covered_steps = math.floor((last - self.t0) / self.tau_th * (1 + 1e-12) + 1e-9)

    def check_steps(self, steps: int) -> None:
        """Raise ConfigError unless the series covers ``steps`` steps of tau_th from t0."""
        if steps > self.covered_steps:
            raise ConfigError(
                f"The temperature file {str(self.path)!r} of the series driver covers {self.covered_steps} "
                f"steps of tau_th = {self.tau_th!r} from t0 = {self.t0!r} to its last time "
                f"{float(self.time[-1])!r}; {steps} steps were asked for."
            )

    def thetas(self, rng: np.random.Generator, steps: int) -> np.ndarray:
        """theta at t = 0 ... steps (in tau_th), shape ``(steps + 1,)``; ``rng`` is unused."""
        self.check_steps(steps)
        times = self.t0 + self.tau_th * np.arange(steps + 1, dtype=np.float64)
        return self.kappa * (np.interp(times, self.time, self.temperature) - self.T0)

    def __repr__(self) -> str:
        return (f"Series(path={str(self.path)!r}, kappa={self.kappa!r}, T0={self.T0!r}, "
                f"tau_th={self.tau_th!r}, t0={self.t0!r}, delimiter={self.delimiter!r})")


# The built-in drivers, by the name a config uses (``driver.name``).
BUILTINS: dict[str, type] = {
    "gaussian_steps": GaussianSteps,
    "ornstein_uhlenbeck": OrnsteinUhlenbeck,
    "sinusoidal": Sinusoidal,
    "ramp": Ramp,
    "constant": Constant,
    "series": Series,
}
