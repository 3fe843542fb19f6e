"""Make the screenshots of docs/guide/pictures-html.md: docs/images/html-{grasp,hand,path}.png.

Each is a page that ``grasptwist plot -o FILE.html`` writes, opened in headless Chromium by the
helper the browser test uses (grasptwist.plot.browser); needs the test extra and Debian's chromium.

    .venv/bin/python docs/make_screenshots.py
"""

import subprocess
import sys
import tempfile
from pathlib import Path

from grasptwist.plot.browser import capture

ROOT = Path(__file__).resolve().parent.parent
SHOTS = [  # (image, grasp file, plot options, capture options)
    ("html-grasp", "box-edge", ["--select", "tip-over-edge"], {}),
    ("html-hand", "trifinger-cube", [], {}),
    # the paper's cylinder turning about x, half-way: the contacts' plane passes the wrist
    (
        "html-path",
        "cylinder",
        ["--path", "turn-x"],
        {
            "scroll_to": 1,
            "before": 'Plotly.animate(figures[1], ["10"], {mode: "immediate", frame: {duration: 0, redraw: true}})',
        },
    ),
]


def main():
    with tempfile.TemporaryDirectory() as tmp:
        for image, grasp, options, shot in SHOTS:
            page = Path(tmp) / f"{image}.html"
            cmd = [
                sys.executable,
                "-m",
                "grasptwist",
                "plot",
                ROOT / "grasps" / f"{grasp}.yaml",
                "-o",
                page,
                "--js-beside",
            ]
            subprocess.run([str(c) for c in cmd + options], check=True, stdout=subprocess.DEVNULL)
            result = capture(page, ROOT / "docs" / "images" / f"{image}.png", size=(1100, 800), **shot)
            if result.errors:
                sys.exit(f"{image}: JavaScript errors: {result.errors}")
            print(result.png.relative_to(ROOT))


if __name__ == "__main__":
    main()
