"""Limits on untrusted input files, shared by the grasp loader and the URDF reader.

Here, not in either reader, so that the URDF reader (which the grasp loader's
``hand:`` section calls) need not import the loader for one constant.
"""

__all__ = ["DEFAULT_MAX_BYTES", "NOT_REGULAR"]

DEFAULT_MAX_BYTES = 1 << 20
"""Default size cap in bytes; larger files are rejected before parsing."""

#: Why a path that is not a regular file (or folder) is not read.
NOT_REGULAR = "not a regular file (a pipe, socket or device)"
