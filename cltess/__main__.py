"""``python -m cltess``: the same as the ``cltess`` command."""
from cltess.cli import run

run()
