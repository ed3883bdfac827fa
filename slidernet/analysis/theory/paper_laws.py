"""The paper's approximate laws of section IV: eq. ``slope``, eq. ``mumaxth`` and the MSD.

- :func:`mean_rearrangements`: the rate of rearrangements (eq. ``slope``);
- :func:`mu_max_leading`: the leading-order growth of mu_max (eq. ``mumaxth``);
- :func:`msd`: the order of magnitude of the centre of mass's diffusion.

Each docstring says how far the law can be trusted; the exact results they
approximate (the moments of mu_max, the number of records) are in
:mod:`~slidernet.analysis.theory.extremes`. Shares with the rest of
:mod:`slidernet.analysis.theory` only the counting convention of ``n`` (the
package's docstring) and the input checks of :mod:`slidernet._validation`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from slidernet._validation import check_array, check_scalar
from slidernet.errors import param_error


def mean_rearrangements(
    sigma_theta: ArrayLike,
    Ntilde: float,
    mu_d: float,
    mu_s_mean: float,
    offset: bool = True,
) -> np.ndarray:
    r"""Mean number of rearrangements per thermal time tau_th (eq. ``slope``).

    With ``offset=True`` this is the paper's phenomenological form

    .. math:: \langle r \rangle = \frac{\sigma_\theta - \mu_d \tilde N}
              {\sqrt{\pi}\,(\bar\mu_s - \mu_d)\,\tilde N},

    and with ``offset=False`` the plain estimate without the shift
    :math:`\mu_d \tilde N`. Both are approximations: docs/model.md (section 4)
    says the first fails when ``sigma_theta`` is below about
    ``2 * mu_d * Ntilde``, and it turns negative, hence meaningless, below
    ``mu_d * Ntilde``. The value is returned as the formula gives it, without
    clipping, so that such a misuse shows.

    Parameters
    ----------
    sigma_theta : float or array_like
        Standard deviation of the dilation theta (dimensionless), > 0; any shape.
    Ntilde : float
        N / (k l0), > 0.
    mu_d : float
        Dynamic friction coefficient, finite.
    mu_s_mean : float
        Mean static friction coefficient (of p(mu_s) before truncation), > mu_d.
    offset : bool
        Subtract the offset mu_d * Ntilde of eq. ``slope`` (default) or not.

    Returns
    -------
    numpy.ndarray
        <r>, rearrangements per tau_th, with the shape of ``sigma_theta``.

    Raises
    ------
    ConfigError
        On a non-finite or non-positive ``sigma_theta`` or ``Ntilde``, a
        non-finite ``mu_d``, or ``mu_s_mean <= mu_d``.

    Examples
    --------
    >>> r = mean_rearrangements(1e-6, Ntilde=1e-7, mu_d=0.5, mu_s_mean=0.6)
    >>> round(float(r), 2)
    53.6
    >>> round(float(mean_rearrangements(1e-6, 1e-7, 0.5, 0.6, offset=False)), 2)
    56.42
    """
    owner = "mean_rearrangements"
    sigma = check_array(sigma_theta, "sigma_theta", owner, "> 0")
    ntilde = check_scalar(Ntilde, "Ntilde", owner, "> 0")
    mu_d = check_scalar(mu_d, "mu_d", owner)
    mu_s_mean = check_scalar(mu_s_mean, "mu_s_mean", owner)
    if not mu_s_mean > mu_d:
        raise param_error("mu_s_mean", owner, f"> mu_d = {mu_d!r}", mu_s_mean)
    shift = mu_d * ntilde if offset else 0.0
    return (sigma - shift) / (math.sqrt(math.pi) * (mu_s_mean - mu_d) * ntilde)


def mu_max_leading(mu_s_mean: float, sigma_mu: float, n: ArrayLike) -> np.ndarray:
    r"""Leading-order growth of mu_max (eq. ``mumaxth``).

    .. math:: \mu_\mathrm{max} \approx \bar\mu_s + \sigma_\mu \sqrt{2 \ln n}

    This is only the leading term of the extreme-value asymptotics of a
    Gaussian: it overestimates the exact mean maximum
    (:func:`mu_max_moments`) by about 0.4 to 0.5 ``sigma_mu`` for n = 1e3 to
    1e6 (0.47 at 1e3 falling to 0.39 at 1e6, for p(mu_s) truncated far below
    its mean), since the next terms,
    ``sigma_mu * (ln ln n + ln 4 pi - 2 gamma) / (2 sqrt(2 ln n))``, decay only
    like ln(ln n) / sqrt(ln n). Where n <= 1 the logarithm is not positive
    and ``mu_s_mean`` is returned; the law carries no information there.

    Parameters
    ----------
    mu_s_mean : float
        Mean static friction coefficient, finite.
    sigma_mu : float
        Standard deviation of mu_s, > 0.
    n : float or array_like
        Number of rearrangements, >= 0 (in the paper, ``<r> t / tau_th``).

    Returns
    -------
    numpy.ndarray
        Predicted mu_max, shape of ``n``.

    Examples
    --------
    >>> mu_max_leading(0.6, 0.01, [1, 1e4]).round(4).tolist()
    [0.6, 0.6429]
    """
    owner = "mu_max_leading"
    mu_s_mean = check_scalar(mu_s_mean, "mu_s_mean", owner)
    sigma_mu = check_scalar(sigma_mu, "sigma_mu", owner, "> 0")
    n_arr = check_array(n, "n", owner, ">= 0")
    log_n = np.log(np.maximum(n_arr, 1.0))
    return mu_s_mean + sigma_mu * np.sqrt(2.0 * log_n)


def msd(sigma_theta: ArrayLike, n: ArrayLike) -> np.ndarray:
    r"""Order-of-magnitude law of the centre-of-mass diffusion.

    .. math:: \langle x_G^2 \rangle \approx \sigma_\theta^2\, l_0^2 \ln n

    (the paper's section IV.C): each exchange of the strongest slider moves
    the centre of mass by about sigma_theta l0, and there are about ln n
    exchanges. Only the order of magnitude and the logarithmic growth are
    claimed; see :func:`mean_records` for the exact number of exchanges.
    Returns 0 where n <= 1.

    Parameters
    ----------
    sigma_theta : float or array_like
        Standard deviation of the dilation theta, > 0.
    n : float or array_like
        Number of rearrangements, >= 0; broadcast against ``sigma_theta``.

    Returns
    -------
    numpy.ndarray
        <x_G^2> in units of l0^2, shape ``np.broadcast(sigma_theta, n).shape``.

    Examples
    --------
    >>> float(msd(1e-6, 1.0))
    0.0
    >>> round(float(msd(1e-6, np.e**2)) / 1e-12, 12)
    2.0
    """
    owner = "msd"
    sigma = check_array(sigma_theta, "sigma_theta", owner, "> 0")
    n_arr = check_array(n, "n", owner, ">= 0")
    return sigma**2 * np.log(np.maximum(n_arr, 1.0))
