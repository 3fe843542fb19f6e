"""The math: screw algebra and the paper's decompositions, pure functions on arrays."""
