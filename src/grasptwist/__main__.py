"""``python -m grasptwist``: the same as the ``grasptwist`` command."""

from grasptwist.cli import main

main()
