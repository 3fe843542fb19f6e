"""``grasptwist schema``: the JSON Schema of grasp files."""

from .exits import EXIT_OK, output_target, run_command
from .options import Debug, Output

__all__ = ["schema"]


def schema(output: Output = None, debug: Debug = False) -> None:
    """Print the JSON Schema of grasp files (for editors with a YAML language server).

    Example:

    \b
        grasptwist schema -o grasp.schema.json
    """
    from ..io.grasp import grasp_schema
    from ..output.records import dumps

    def write_schema():
        with output_target(output) as out:
            out.write(dumps(grasp_schema(), indent=True) + b"\n")
        return EXIT_OK

    run_command(debug, write_schema)
