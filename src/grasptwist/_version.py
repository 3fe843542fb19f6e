"""The package version, in a module of its own so that the command line reads it without the public facade."""

__version__ = "0.6.0"
