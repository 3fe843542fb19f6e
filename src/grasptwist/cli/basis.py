"""``grasptwist basis``: each grasp's basis screws, their Klein products and conditioning."""

from .diagnostics import Warnings
from .exits import run_command
from .options import (
    ALL,
    AllowOutside,
    Debug,
    Digits,
    Json,
    MaxBytes,
    Method,
    Order,
    OrderOption,
    Output,
    Paths,
    Quiet,
    RecordFormat,
    RecordFormatOption,
    SurfaceTol,
    WarningsOption,
    Workers,
    reading_option,
)
from .records import OutputSettings, write_records

__all__ = ["basis"]


def basis(
    paths: Paths,
    method: Method = ALL,
    fmt: RecordFormatOption = RecordFormat.table,
    json_: Json = False,
    output: Output = None,
    digits: Digits = 4,
    order: OrderOption = Order.omega_v,
    max_bytes: MaxBytes = None,
    surface_tol: SurfaceTol = None,
    allow_outside: AllowOutside = False,
    workers: Workers = 0,
    quiet: Quiet = False,
    warnings: WarningsOption = Warnings.summary,
    debug: Debug = False,
) -> None:
    """Show each grasp's basis screws Sigma, Psi, Theta, their Klein products and conditioning.

    Example (the paper's eqs. 16-18, with unit Psi):

    \b
        grasptwist basis grasps/cylinder.yaml --method off-tangent
    """
    from ..run.families import COMMANDS
    from ..run.options import TwistOptions
    from ..run.pipeline import Job

    job = Job(
        command=COMMANDS["basis"],
        fmt="json" if json_ else fmt.value,
        max_bytes=max_bytes,
        reading=reading_option(surface_tol, allow_outside),
        order=order.value,
        options=TwistOptions(method=method.value),
    )
    settings = OutputSettings(output, quiet, warnings, workers, {"digits": digits, "order": order.value})
    run_command(debug, lambda: write_records(job, paths, settings))
