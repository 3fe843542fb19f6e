"""Where the tests' files are, for every test module whatever folder of ``tests/`` it sits in."""

from pathlib import Path

#: The tests' root folder: the helpers, ``corpus/``, ``golden/`` and ``invalid_grasps/``.
TESTS = Path(__file__).resolve().parent

#: The repository's root.
ROOT = TESTS.parent

#: The bundled grasps.
GRASPS = ROOT / "grasps"
