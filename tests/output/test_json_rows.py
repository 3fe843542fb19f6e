"""The template encoder writes, byte for byte, what encoding each record writes."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from grasp_gen import grasps
from grasptwist.engine.decompose import decompose_tangent
from grasptwist.engine.screws import direction
from grasptwist.output.json_rows import encode_records
from grasptwist.output.records import dumps, records
from grasptwist.run.batch import resolve_arrays


def block(seed, n, method, wrists, quotes=True):
    rng = np.random.default_rng(seed)
    points, normals, wrist, twist = grasps(rng, n)
    twist[: n // 4] = np.round(twist[: n // 4], 1)  # short numbers, -0.0 and zeros too
    twist[1] = 0.0
    wrist[2] = points[2].mean(0)  # a failing off-tangent row
    points[3, 1] = points[3, 0]  # a row failing both methods
    wrist[4] = points[4].mean(0) + 1e-6 * np.cross(
        points[4, 1] - points[4, 0], points[4, 2] - points[4, 0]
    )  # a warning
    twist[5] = [0, 0, 0, 0, 0, 1e-300]
    # verdicts that need templates of their own: a rotation about the wrist, a twist in the tangent planes
    twist[6, 3:] = -np.cross(twist[6, :3], wrist[6])
    twist[7] = decompose_tangent(points[7], direction(normals[7]), np.zeros(6)).theta[1]
    if wrists == "none":
        wrist = None
    elif wrists == "some":
        wrist[::3] = np.nan
    odd = (
        'quote " and \\ and \u00e9' if quotes else "comma, \\ and \u00e9\x01"
    )  # labels without a quote take a faster path
    names = [f"g{i}" if i % 5 else f"{odd}{i}" for i in range(n)]
    return resolve_arrays(
        points,
        direction(normals),
        wrist,
        twist,
        method,
        file=["a%s.yaml"] * n,
        grasp=names,
        units=["m" if i % 2 else None for i in range(n)],
    )


@settings(max_examples=25, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(8, 40),
    st.sampled_from(["both", "off-tangent", "tangent"]),
    st.sampled_from(["omega-v", "v-omega"]),
    st.sampled_from(["all", "some", "none"]),
    st.booleans(),
)
def test_template_texts_equal_encoding_each_record(seed, n, method, order, wrists, quotes):
    b = block(seed, n, method, wrists, quotes)
    texts, talking = encode_records(b, order, records, dumps)
    expected = [dumps(r) for r in records(b, order)]
    assert texts == expected
    if method != "tangent" and wrists == "all":
        assert b'"about_wrist":true' in texts[6] and b'"about_wrist":false' in texts[0]
    if method != "off-tangent":
        assert b'"in_tangent_planes":true' in texts[7] and b'"moves":[[],[0,2],[],[],[],[]]' in texts[7]
    assert sorted(dumps(r) for r in talking) == sorted(
        e for e, r in zip(expected, records(b, order)) if not r["ok"] or r["warnings"]
    )


def test_most_rows_take_the_template():
    b = block(3, 200, "both", "all")
    calls = []

    def counting(part, order):
        calls.append(len(part))
        return records(part, order)

    encode_records(b, "omega-v", counting, dumps)
    assert sum(calls) < 20 + 2  # the few non-plain rows one by one, plus one marker row per template
