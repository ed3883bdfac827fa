"""``python -m slidernet``: the ``slidernet`` command (:mod:`slidernet.cli`), where it is not on PATH."""

from slidernet.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
