"""Outputs: records (the JSON contract), their encodings and writers, tables."""
