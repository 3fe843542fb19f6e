"""The YAML parsers the loader's tests run on, and a grasp document to build test documents from."""

import yaml

#: The YAML parsers the loader can run on here: the pure one, and libyaml's when present.
LOADERS = [yaml.SafeLoader] + ([yaml.CSafeLoader] if yaml.__with_libyaml__ else [])

#: Three valid contacts (the paper's Example 1), to build test documents from.
CONTACTS = """\
contacts:
  - point: [1, 0, 0]
    normal: [-1, 0, 0]
  - point: [-0.5, 0.866, 0]
    normal: [0.5, -0.866, 0]
  - point: [-0.5, -0.866, 0]
    normal: [0.5, 0.866, 0]
"""
