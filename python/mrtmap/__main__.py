"""The ``mrtmap`` command line (``python -m mrtmap …``, or the ``mrtmap`` command the wheel
installs): the same program as the Rust binary, run through the native module."""

import sys

from . import _mrtmap


def main() -> int:
    """Runs the command line with ``sys.argv`` and returns its exit code."""
    return _mrtmap.cli_main(["mrtmap", *sys.argv[1:]])


if __name__ == "__main__":
    sys.exit(main())
