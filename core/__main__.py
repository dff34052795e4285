"""``python -m cavex``: the ``cavex`` command line (:mod:`cavex.verification.cli`)."""

import sys

from cavex.verification.cli import main

if __name__ == "__main__":
    sys.exit(main())
