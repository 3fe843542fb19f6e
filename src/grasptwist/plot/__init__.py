"""Pictures of a grasp and a twist: the scene as data, rendered by matplotlib."""

from .scene import *  # noqa: F401,F403
from .scene import __all__  # noqa: F401
