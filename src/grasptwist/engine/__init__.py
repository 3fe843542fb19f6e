"""The math: pure functions on arrays, no input or output.

- ``screws``: screw algebra (Klein form, lines, twists), also on three separate components;
- ``formulas``: the paper's formulas as written, one function each (the reference);
- ``kernels``: the same in closed form, for one grasp in floats or a chunk of rows in numpy;
- ``decompose``: the public functions and their results, running the kernels;
- ``prepared``: many twists on one grasp by a precomputed linear map;
- ``checks``: validation of the arguments; ``degeneracy``: status codes and tolerances.
"""
