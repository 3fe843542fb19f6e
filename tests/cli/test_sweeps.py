"""Sweeps into a degenerate grasp, through the engine and through the CLI's JSON.

The wrist moves toward the contacts' plane (off-tangent basis: every
[Sigma_i|Psi_i] -> 0), and a contact moves toward the line of the other two
(both bases).  Along the way amplitudes must grow smoothly, a warning must
appear once the conditioning figure drops below CONDITION_WARNING, the
degenerate end must fail with its specific code, and no ok record may hold a
NaN or an infinity.
"""

from dataclasses import dataclass

import numpy as np
import pytest

import grasptwist as gt
from grasptwist.engine.degeneracy import CONDITION_WARNING
from hostile import assert_no_crash, jsonl, run

STEPS = np.r_[np.logspace(0, -12, 13), 0.0]  # 1, 1e-1, ..., 1e-12, 0
TWIST = np.array([0.3, -0.2, 1.0, 0.1, 0.5, -0.4])
EX1 = np.array([[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]], float)
# normals well clear of every tangent degeneracy for the triangles below
NORMALS = np.array([[1, 0.3, 0.5], [-1, 0.2, 0.6], [0.1, -1, 0.4]])


@dataclass(frozen=True)
class Sweep:
    """Grasps along one path into a degeneracy, one per entry of STEPS."""

    name: str
    points: np.ndarray  # (n, 3, 3)
    wrist: np.ndarray  # (n, 3)
    normals: np.ndarray  # (3, 3)
    methods: dict  # method -> the codes allowed on the way, the last one that at STEPS[-1] = 0
    one_over_step: tuple  # methods whose amplitudes grow like 1/step once the step is small


def wrist_sweep():
    wrist = np.c_[np.full(len(STEPS), 0.1), np.full(len(STEPS), 0.2), STEPS]
    return Sweep("wrist-to-plane", np.broadcast_to(EX1, (len(STEPS), 3, 3)), wrist, NORMALS,
                 {"off_tangent": ("wrist-coplanar",)}, ("off_tangent",))  # fmt: skip


def collinear_sweep():
    points = np.array([[[-1, 0, 0], [1, 0, 0], [0.2, d, 0]] for d in STEPS], float)
    # the tangent basis degenerates faster ([Theta_i|Sigma_i] ~ d^2) and fails first with its own code
    return Sweep("contact-to-line", points, np.broadcast_to([0, 0, 1.0], (len(STEPS), 3)), NORMALS,
                 {"off_tangent": ("collinear-contacts",), "tangent": ("theta-sigma-zero", "collinear-contacts")},
                 ("off_tangent",))  # fmt: skip


SWEEPS = [wrist_sweep(), collinear_sweep()]


def engine(sweep):
    """Each method's result over the sweep, keyed like the JSON records."""
    out = {}
    if "off_tangent" in sweep.methods:
        out["off_tangent"] = gt.decompose_off_tangent(sweep.points, sweep.wrist, TWIST)
    if "tangent" in sweep.methods:
        out["tangent"] = gt.decompose_tangent(sweep.points, np.broadcast_to(sweep.normals, sweep.points.shape), TWIST)
    return out


def amplitudes(result):
    """(n, 6) amplitudes of either method."""
    pair = (result.x, result.y) if isinstance(result, gt.OffTangentResult) else (result.alpha, result.beta)
    return np.concatenate(pair, axis=-1)


def as_yaml(sweep):
    """The sweep as one grasp file, a document per step (floats written exactly)."""
    vec = lambda v: "[" + ", ".join(repr(float(x)) for x in v) + "]"  # noqa: E731
    docs = []
    for k, step in enumerate(STEPS):
        contacts = "".join(
            f"  - {{point: {vec(p)}, normal: {vec(n)}}}\n" for p, n in zip(sweep.points[k], sweep.normals)
        )
        docs.append(
            f"name: step-{step!r}\nwrist: {vec(sweep.wrist[k])}\ncontacts:\n{contacts}twists:\n  - screw: {vec(TWIST)}\n"
        )
    return "---\n".join(docs)


@pytest.mark.parametrize("sweep", SWEEPS, ids=lambda s: s.name)
def test_the_engine_grows_smoothly_then_fails_specifically(sweep):
    for method, r in engine(sweep).items():
        allowed = sweep.methods[method]
        ok = np.asarray(r.ok)
        codes = [gt.Status(int(s)).code for s in r.status]
        first_bad = int(np.argmin(ok))
        # ok down to a small step, then failed to the end, with the expected codes only
        assert ok[:first_bad].all() and not ok[first_bad:].any() and STEPS[first_bad - 1] <= 1e-3, codes
        assert set(codes[first_bad:]) <= set(allowed) and codes[-1] == allowed[-1], codes
        a = amplitudes(r)
        assert np.isfinite(a[ok]).all() and np.isnan(a[~ok]).all()
        peak = np.abs(a[ok]).max(axis=1)
        assert np.all(np.diff(peak) > 0), peak  # monotone
        assert np.all(np.diff(r.conditioning[ok]) < 0)
        if method in sweep.one_over_step:
            small = STEPS[:first_bad] <= 1e-3
            np.testing.assert_allclose(
                peak[small] * STEPS[:first_bad][small], (peak * STEPS[:first_bad])[small][0], rtol=1e-2
            )
        # the threshold is crossed inside the sweep, so the warning band is not empty
        assert (r.conditioning[ok] < CONDITION_WARNING).any() and (r.conditioning[ok] >= CONDITION_WARNING).any()


@pytest.mark.parametrize("sweep", SWEEPS, ids=lambda s: s.name)
def test_the_cli_reports_the_same_with_warnings_and_errors(sweep, tmp_path):
    path = tmp_path / f"{sweep.name}.yaml"
    path.write_text(as_yaml(sweep))
    method = "both" if len(sweep.methods) == 2 else "off-tangent"
    result, _ = run("resolve", path, "-f", "jsonl", "--method", method)
    assert_no_crash(result.stdout + result.stderr)
    assert result.exit_code == 1 and result.python_warnings == []
    records = jsonl(result.stdout)  # no NaN or infinity in any ok record
    assert [r["grasp"] for r in records] == [f"step-{s!r}" for s in STEPS]
    warned = 0
    for method, r in engine(sweep).items():
        label = method.replace("_", "-")
        for k, rec in enumerate(records):
            got = rec[method]
            if not r.ok[k]:
                assert got["error"]["code"] == gt.Status(int(r.status[k])).code and rec["ok"] is False
                continue
            np.testing.assert_allclose(np.concatenate(_amplitudes_of(got)), amplitudes(r)[k], rtol=1e-12, atol=0)
            assert got["conditioning"] == pytest.approx(r.conditioning[k], rel=1e-12)
            warns = [w for w in rec["warnings"] if w.startswith(f"{label} basis is nearly degenerate")]
            assert len(warns) == (r.conditioning[k] < CONDITION_WARNING), (
                rec["grasp"],
                got["conditioning"],
                rec["warnings"],
            )
            warned += len(warns)
        assert records[-1][method]["error"]["code"] == sweep.methods[method][-1]
    # (the sweeps' normals point outward, which gets a warning of its own per record)
    warning_lines = [line for line in result.stderr.splitlines() if "basis is nearly degenerate" in line]
    assert warned > 0 and len(warning_lines) == warned
    assert all(line.startswith(f"{path}: grasp 'step-") for line in warning_lines)


def _amplitudes_of(method_record):
    if "x" in method_record:
        return method_record["x"], method_record["y"]
    return method_record["alpha"], method_record["beta"]
