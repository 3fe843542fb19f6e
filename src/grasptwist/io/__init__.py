"""Inputs: which files a command reads, grasp files (YAML) and array data sets."""
