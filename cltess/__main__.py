"""``python -m cltess``: the same as the ``cltess`` command."""
import sys

from cltess.cli import main

sys.exit(main())
