"""`import fm2uav` stays light (lazy subpackages) and figures never touch pyplot state."""

from __future__ import annotations

import subprocess
import sys

import pytest

HEAVY = ("matplotlib", "plotly", "dask", "distributed", "pyarrow", "ompl")


def _run(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, check=True)
    return out.stdout.strip()


def test_import_fm2uav_loads_no_plotting_dask_or_parquet():
    code = ("import fm2uav, sys; "
            f"print(','.join(m for m in {HEAVY!r} if m in sys.modules))")
    assert _run(code) == ""


def test_lazy_subpackages_load_on_first_access():
    code = ("import fm2uav, sys; before = 'fm2uav.viz' in sys.modules; "
            "v = fm2uav.viz; print(before, v.__name__, 'matplotlib' in sys.modules, "
            "'viz' in dir(fm2uav))")
    assert _run(code) == "False fm2uav.viz True True"


def test_unknown_attribute_is_an_attribute_error():
    import fm2uav

    with pytest.raises(AttributeError, match="no attribute 'nonexistent'"):
        fm2uav.nonexistent  # noqa: B018


def test_figures_are_built_without_pyplot():
    # a Figure made by viz is not registered with pyplot: nothing to close, nothing leaks
    code = (
        "import sys, numpy as np\n"
        "from fm2uav import World, plan\n"
        "from fm2uav.viz import plan_figure\n"
        "w = World(np.zeros((30, 20), bool), spacing=1.0)\n"
        "fig = plan_figure(plan(w, (2.0, 2.0), (25.0, 15.0)))\n"
        "import io; fig.savefig(io.BytesIO(), format='png')\n"
        "print('matplotlib.pyplot' in sys.modules)\n"
    )
    assert _run(code) == "False"
