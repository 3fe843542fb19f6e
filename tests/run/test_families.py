"""The families of rows (run/families.py): a job holds its family's options, and a command
added to the registry alone runs through the pipeline and the output formats (issue 28)."""

import io
import json

import pytest

from grasptwist.output.formats import FORMATS
from grasptwist.run.batch import ZERO_TWIST
from grasptwist.run.families import COMMANDS, FAMILIES, WRENCH, Command
from grasptwist.run.forces import closure_fields
from grasptwist.run.options import ForceOptions, SynthesisOptions, TwistOptions
from grasptwist.run.pipeline import Job, outputs
from places import GRASPS


def test_a_job_holds_its_familys_options_and_what_its_command_fixes():
    assert Job().options == TwistOptions()  # resolve, a command line without options
    assert Job(command=COMMANDS["forces"]).options == ForceOptions()
    basis = Job(command=COMMANDS["basis"], options=TwistOptions(method="tangent"))
    assert basis.options.twists == (ZERO_TWIST,) and basis.options.method == "tangent"
    with pytest.raises(TypeError, match="forces takes ForceOptions, got TwistOptions"):
        Job(command=COMMANDS["forces"], options=TwistOptions())


def test_every_command_offers_only_formats_its_family_can_write():
    for command in COMMANDS.values():
        assert command.family in FAMILIES
        assert list(command.formats) == [f for f in FORMATS if f in command.formats]  # in --help's order
        if "parquet" in command.formats:
            assert command.family.columns().typed_header is not None, command.name
    with pytest.raises(ValueError, match="no output format"):
        Command("x", WRENCH, ("yaml",), lambda block, job: [], "table.TableWriter")


def _written(job, paths):
    buf = io.BytesIO()
    w = FORMATS[job.fmt].open(buf, job)
    for o in outputs(job, paths, w):
        for encoded in o.encoded:
            w.write(encoded)
    w.close()
    return buf.getvalue()


def test_a_command_added_to_the_registry_alone_runs_through_every_layer():
    """A new command over the wrench family's rows (each row's closure alone), given to a Job:
    the pipeline, the JSON formats and CSV take it with no other change."""

    def closures(block, job):
        return [
            {"grasp": block.grasp[i], **fields, "warnings": [], "ok": True}
            for i, fields in enumerate(closure_fields(block))
        ]

    command = Command("closures", WRENCH, ("json", "jsonl", "csv"), closures, "table.CheckTableWriter")
    paths = [str(GRASPS / "sphere.yaml"), str(GRASPS / "polyhedron.yaml")]
    recs = [json.loads(line) for line in _written(Job(command=command, fmt="jsonl"), paths).splitlines()]
    forces = json.loads(_written(Job(command=COMMANDS["forces"], fmt="json"), paths))
    assert [r["grasp"] for r in recs] == [r["grasp"] for r in forces]
    assert [r["closure_friction"] for r in recs] == [r["closure"]["closure_friction"] for r in forces]
    assert json.loads(_written(Job(command=command, fmt="json"), paths)) == recs
    csv = _written(Job(command=command, fmt="csv"), paths).decode().splitlines()
    assert csv[0].startswith("file,grasp,wrench,ok,error,") and len(csv) == 1 + len(recs)  # the family's columns


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({"mass": -1.0}, "mass must be a finite number > 0"),
        ({"tip_radius": float("nan")}, "tip_radius must be a finite"),
    ],
)
def test_the_run_s_options_check_what_changes_the_object_and_the_hand_for_every_way_in(options, words):
    # grasptwist.dask passes its keywords straight to SynthesisOptions: they are refused there, as on the command line
    assert SynthesisOptions(mass=2.0, tip_radius=0.01).mass == 2.0
    with pytest.raises(ValueError, match=words):
        SynthesisOptions(**options)
