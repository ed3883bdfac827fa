"""The rules a scene and the checks of a configuration share.

Which kernel a scene runs on (:func:`choose_kernel`) and when the tilt test
of mu_eff is made (:func:`choose_tilt_at`, refused with
:data:`PAIR_TILT_ONLY`). Each is written once, here, so that a
configuration is checked by the rule its scene will follow; they take plain
values, not the tables, so that the scene (:mod:`slidernet.solver.scene`)
calls them as the tables do.
"""

from __future__ import annotations


def choose_kernel(requested: str, two_slider: bool, dim: int, node_state: bool) -> str:
    """The kernel a scene runs on: the one rule, used by the scene and by the checks of a configuration.

    ``auto`` gives ``pair`` (scalars only) for the paper's two sliders unless
    the scene needs per-node state (``node_state``: the event catalogue of the observables "events" and
    "creep", each node's last slip of "contact_age"; on a 2-node chain the network kernel gives the pair
    kernel's bits, ARCHITECTURE.md invariant 6), and else the
    network kernel of the dimension: ``csr`` in 1D, ``vec`` in 2D. A kernel
    named in ``solver.kernel`` is returned as it is (the scene refuses one
    that cannot run its network).

    >>> [choose_kernel("auto", True, 1, False), choose_kernel("auto", True, 1, True)]
    ['pair', 'csr']
    >>> choose_kernel("auto", False, 2, False)
    'vec'
    """
    if requested != "auto":
        return requested
    if two_slider and not node_state:
        return "pair"
    return "csr" if dim == 1 else "vec"


#: Why ``mu_eff_at = "rearrangements"`` is refused: the one message, from :func:`choose_tilt_at`.
PAIR_TILT_ONLY = ("'mu_eff_at = \"rearrangements\"' (the appendix's tilt test before every rearrangement) "
                  "needs a 1D pair of sliders with unit normal loads and no f_ext; use 'records' "
                  "(the network tilt test at the recorded times)")


def choose_tilt_at(requested: str, pair_tilt: bool) -> str:
    """When the tilt test of mu_eff is made: the one rule, used by the scene and by the checks of a configuration.

    ``auto`` gives ``"rearrangements"`` (the appendix's test before every
    rearrangement) where it applies, ``"records"`` (the network tilt test at
    the recorded times) elsewhere; a value named in ``mu_eff_at`` is returned
    as it is, and ``"rearrangements"`` where the appendix's test does not
    apply is refused.

    Parameters
    ----------
    requested : {"auto", "rearrangements", "records"}
        The configuration's ``mu_eff_at``.
    pair_tilt : bool
        The appendix's test applies to the network
        (:func:`~slidernet.model.network.pair_tilt_applies`).

    Returns
    -------
    {"rearrangements", "records"}

    Raises
    ------
    ValueError
        ``"rearrangements"`` without ``pair_tilt``; the message is
        :data:`PAIR_TILT_ONLY` (a validator's ValueError, which pydantic
        reports with the field names).

    Examples
    --------
    >>> choose_tilt_at("auto", True), choose_tilt_at("auto", False)
    ('rearrangements', 'records')
    """
    if requested == "auto":
        return "rearrangements" if pair_tilt else "records"
    if requested == "rearrangements" and not pair_tilt:
        raise ValueError(PAIR_TILT_ONLY)
    return requested
