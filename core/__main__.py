"""``python -m cavex``: the ``cavex`` command line (:mod:`cavex.verification.cli`)."""

import sys

from cavex.verification.cli import console

if __name__ == "__main__":
    sys.exit(console())
