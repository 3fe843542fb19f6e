"""Grasps run in MuJoCo: the scene as MJCF (:mod:`.scene`, with :mod:`.contact`'s settings), the
six-direction hold test (:mod:`.hold`) and a path executed (:mod:`.path`).  Beside ``plot``: it imports the model and the engine
only, and MuJoCo (the ``sim`` extra) where it runs."""
