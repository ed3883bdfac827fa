"""The reproduction of Geminard & Bertin (2010): ``slidernet paper`` (see :mod:`slidernet.paper.reproduction`)."""

from slidernet.paper.reproduction import FULL, QUICK, Preset, main, reproduce

__all__ = ["FULL", "QUICK", "Preset", "main", "reproduce"]
