"""Grasp synthesis: contact triples on an object's surface, scored in batches, refined, verified."""
