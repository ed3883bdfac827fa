"""The plugin contract under its first name: see :mod:`slidernet.plugins.contract`.

Plugin authors' tests import ``slidernet.testing``; it stays importable.
"""

from slidernet.plugins.contract import *  # noqa: F403
from slidernet.plugins.contract import __all__  # noqa: F401
