"""The layers of ARCHITECTURE.md, lowest first: ``tests/api/test_layers.py`` holds the imports to them,
``tests/api/test_api.py`` takes the public modules from the last."""

#: Lowest first.  A module may import its own group and any group of a lower layer;
#: groups of one layer are independent of each other.
LAYERS = [
    [
        "grasptwist.model",
        "grasptwist.codes",
        "grasptwist.extras",
        "grasptwist._version",
        "grasptwist._moved",
    ],  # data types and codes, no math
    ["grasptwist.engine"],  # the math on arrays
    ["grasptwist.io"],  # files in
    ["grasptwist.results"],  # the registry of result kinds and their fields
    ["grasptwist.output", "grasptwist.plot", "grasptwist.sim"],  # records and tables out; pictures; MuJoCo scenes
    ["grasptwist.run"],  # batches, workers, streams, the -o target: engine over inputs into outputs
    ["grasptwist.cli"],  # the command line
    # the public facades and entry points: nothing inside the package imports them
    [
        "grasptwist",
        "grasptwist.screws",
        "grasptwist.hand",
        "grasptwist.forces",
        "grasptwist.path",
        "grasptwist.pictures",
        "grasptwist.objects",
        "grasptwist.dask",
        "grasptwist.__main__",
    ],
]
