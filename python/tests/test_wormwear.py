"""The Python package against the CLI (same numbers, same files), its input errors, its
variants, sweeps locally / through the CLI / on a Dask cluster, resume and interrupts."""

import json
import math
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pandas as pd
import pytest

import wormwear

from conftest import EXAMPLES, ROOT, cli_path

RESULT_COLUMNS = [
    "max_pressure_pa",
    "contact_area_fraction",
    "te_p2p_rad",
    "power_balance",
    "efficiency",
    "life_cycles",
    "backlash_increase_end_m",
    "max_wear_end_m",
    "backlash_limit_m",
    "cycles_to_backlash_limit",
]


def files_of(directory):
    d = pathlib.Path(directory)
    return {p.name: p.read_bytes() for p in d.iterdir() if p.is_file() and p.name != ".wormwear.lock"}


def assert_same_files(one, other):
    """The same files in two directories, byte for byte."""
    a, b = files_of(one), files_of(other)
    assert a.keys() == b.keys()
    for name in a:
        assert a[name] == b[name], name


def assert_close(a, b, path="", rel=1e-12):
    """Two JSON values equal, numbers to `rel` relative."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), path
        for k in a:
            assert_close(a[k], b[k], f"{path}.{k}", rel)
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), path
        for k, (x, y) in enumerate(zip(a, b)):
            assert_close(x, y, f"{path}[{k}]", rel)
    elif isinstance(a, float) or isinstance(b, float):
        if a is None or b is None:
            assert a == b, path
        else:
            assert math.isclose(a, b, rel_tol=rel, abs_tol=1e-300), f"{path}: {a} != {b}"
    else:
        assert a == b, path


def test_ltca_equals_the_cli_in_numbers_and_files(cli, design_file, tmp_path):
    cli("-q", "ltca", design_file, "-o", tmp_path / "cli", "--map-position", "2")
    gear = wormwear.load(str(design_file))
    r = wormwear.run(gear, stages=["ltca"], map_position=2)
    written = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert_close(r.summary, written)
    # The acceptance line: the value the CLI writes.
    assert r.ltca.max_pressure_pa == written["ltca"]["max_pressure_pa"]
    # Tables at full precision against the files (rounded to 11 significant digits).
    for name, frame in [("ltca_positions", r.ltca.positions), ("ltca_pressures", r.ltca.pressures)]:
        file = pd.read_csv(tmp_path / "cli" / f"{name}.csv")
        assert list(frame.columns) == list(file.columns)
        np.testing.assert_allclose(frame.to_numpy(float), file.to_numpy(float), rtol=6e-11, atol=0)
    pattern = r.ltca.pattern
    # 60 columns; 40 nominal rows and the band's finer rows at the worm-tip trace (58 here)
    rows, columns = pattern.values.shape
    assert columns == 60 and rows > 40 and np.nanmax(pattern.values) == r.ltca.max_pressure_pa
    # The radius grows up the tooth, z across the face.
    assert np.all(np.diff(pattern.r_mm[:, 30]) > 0) and np.all(np.diff(pattern.z_mm[20, :]) != 0)
    # The equivalent pressure below the flank (MODEL §8.1) as a map and per cell.
    assert np.nanmax(r.ltca.equivalent.values) == r.ltca.equivalent_pressure_max_pa
    assert r.ltca.pressures["equivalent_pressure_pa"].max() > 0
    # The friction (MODEL §13): the section and the table equal the file's, on the flank grid;
    # the local coefficient is positive where a cell is loaded.
    assert r.friction.efficiency == written["friction"]["efficiency"]
    file = pd.read_csv(tmp_path / "cli" / "friction_map.csv")
    assert list(r.friction.table.columns) == list(file.columns)
    np.testing.assert_allclose(r.friction.table.to_numpy(float), file.to_numpy(float), rtol=6e-11, atol=0, equal_nan=True)
    assert r.friction.coefficient.values.shape == pattern.values.shape
    mu = r.friction.coefficient.values
    assert 0 < np.nanmin(mu) <= np.nanmax(mu) <= r.friction.friction["mean_coefficient"] * 10
    # The safety table (MODEL §9.1) as a DataFrame, the file's rows.
    safety = r.rating.safety
    file = pd.read_csv(tmp_path / "cli" / "rating.csv")
    assert list(safety["symbol"]) == list(file["symbol"]) and "S_H" in list(safety["symbol"])
    np.testing.assert_allclose(safety["value"].to_numpy(float), file["value"].to_numpy(float), rtol=1e-6)
    assert list(safety["verdict"]) == list(file["verdict"])
    r.write(tmp_path / "py")
    assert_same_files(tmp_path / "cli", tmp_path / "py")


def test_a_run_with_a_life_equals_the_cli(cli, design_file, tmp_path):
    cli("-q", "run", design_file, "-o", tmp_path / "cli", "--cycles", "20000", "--step-cycles", "10000")
    r = wormwear.run(wormwear.load(str(design_file)), cycles=20000, step_cycles=10000)
    assert r.stages == ["geometry", "tca", "ltca", "wear", "report"]
    written = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert_close(r.summary, written)
    records = r.wear.records
    assert list(records["step"]) == [0, 1, 2]
    file = pd.read_csv(tmp_path / "cli" / "wear_steps.csv")
    np.testing.assert_allclose(records.to_numpy(float), file.to_numpy(float), rtol=6e-11, atol=0)
    # The wear map: depth zero where nothing wore, the maximum the records' last max_wear_m.
    assert math.isclose(np.nanmax(r.wear.depth.values), records["max_wear_m"].iloc[-1], rel_tol=1e-12)
    r.write(tmp_path / "py")
    assert_same_files(tmp_path / "cli", tmp_path / "py")
    # The two runs side by side (wormwear compare): the same numbers, as the CLI writes them.
    frame = wormwear.compare([tmp_path / "cli", tmp_path / "py"], tmp_path / "compare")
    assert list(frame.columns) == ["unit", "cli", "py"]
    assert frame.loc["Worm torque", "cli"] == pytest.approx(60.0)
    np.testing.assert_array_equal(frame["cli"].to_numpy(float), frame["py"].to_numpy(float))
    assert (tmp_path / "compare" / "compare.html").exists()
    cli("-q", "compare", tmp_path / "cli", tmp_path / "py", "-o", tmp_path / "compare-cli")
    assert (tmp_path / "compare-cli" / "compare.csv").read_text() == (
        tmp_path / "compare" / "compare.csv"
    ).read_text()


def test_input_errors_raise_with_the_cli_message_and_every_problem(cli, design_file, tmp_path):
    gear = wormwear.load(str(design_file))
    document = gear.to_dict()
    document["conditions"]["worm_torque_nm"] = -5.0
    document["worm"]["pressure_angle_deg"] = 85.0
    with pytest.raises(wormwear.InputError) as e:
        wormwear.GearSet.from_dict(document)
    fields = {p[0] for p in e.value.problems}
    assert {"conditions.worm_torque_nm", "worm.pressure_angle_deg"} <= fields
    # The same message as the CLI's for the same file.
    bad = tmp_path / "bad.toml"
    bad.write_text(design_file.read_text().replace("worm_torque_nm = 60.0", "worm_torque_nm = -5.0"))
    out = cli("check", bad, check=False)
    assert out.returncode == 2
    with pytest.raises(wormwear.InputError) as e:
        wormwear.load(str(bad))
    assert str(e.value) in out.stderr
    # Variants: an unknown field, a value out of range, a path through a value.
    with pytest.raises(wormwear.InputError, match="worm_torq_nm") as e:
        gear.with_(**{"conditions.worm_torq_nm": 5})
    # The dotted name, not a line of a document the user never wrote; the class's own name.
    assert str(e.value).startswith("with_(conditions.worm_torq_nm): unknown field"), str(e.value)
    assert "line" not in str(e.value) and e.value.problems[0][0] == "conditions.worm_torq_nm"
    assert wormwear.InputError.__name__ == "InputError"
    with pytest.raises(wormwear.InputError, match="conditions.worm_speed_rpm"):
        gear.with_(**{"conditions.worm_speed_rpm": -1})
    with pytest.raises(wormwear.InputError, match="is a value"):
        gear.with_(**{"worm.profile.x": 1})
    with pytest.raises(OSError):
        wormwear.load(str(tmp_path / "missing.toml"))
    # A life without plan, an override out of range.
    with pytest.raises(wormwear.InputError, match="step_wear_um = 0"):
        wormwear.run(gear, stages=["wear"], step_wear_um=0)


def test_variants_and_pickling(design_file):
    import pickle

    gear = wormwear.load(str(design_file))
    heavy = gear.with_(**{"conditions.worm_torque_nm": 90})
    assert heavy.to_dict()["conditions"]["worm_torque_nm"] == 90
    assert gear.to_dict()["conditions"]["worm_torque_nm"] == 60.0  # unchanged
    assert heavy.validated()["conditions"]["torque"] == {"Worm": 90.0}
    again = pickle.loads(pickle.dumps(heavy))
    assert again.to_dict() == heavy.to_dict() and again.file == heavy.file
    # A field removed takes its default.
    assert "wear" not in gear.with_(wear=None).to_dict()


def test_the_grid_varies_its_first_name_slowest_in_the_given_order():
    # Issue 59: the names were sorted alphabetically (the README says the first varies slowest).
    grid = {"lubricant.composite_roughness_um": [0.5, 1.0], "conditions.worm_torque_nm": [30.0, 60.0, 90.0]}
    parameters, variants = wormwear._variants(grid, None)
    assert parameters == list(grid)
    firsts = [values["lubricant.composite_roughness_um"] for _, values in variants]
    assert firsts == [0.5, 0.5, 0.5, 1.0, 1.0, 1.0]


def rows_of(frame):
    """Rows comparable across engines: everything but the wall time."""
    return frame.drop(columns=["seconds"]).sort_values("variant").reset_index(drop=True)


GRID = {
    "conditions.worm_torque_nm": [30.0, 90.0],
    "lubricant.composite_roughness_um": [0.5, -1.0, 1.0],
}


def test_a_sweep_gives_the_same_rows_locally_through_the_cli_and_on_dask(cli, fast_gear_file, tmp_path):
    base = wormwear.load(str(fast_gear_file))
    local = wormwear.sweep(base, GRID, stages=["ltca", "wear"], cycles=20000, step_cycles=10000)
    assert len(local) == 6
    # The invalid roughness fails with its field named; the others go on.
    failed = local[~local["ok"]]
    assert list(failed["variant"]) == ["v2", "v5"]
    assert failed["error"].str.contains("lubricant.composite_roughness_um").all()
    assert local[local["ok"]]["backlash_increase_end_m"].gt(0).all()
    # Wear grows with the load and with the roughness (a thinner film ratio).
    by = local.set_index("variant")["backlash_increase_end_m"]
    assert by["v4"] > by["v1"] and by["v3"] > by["v1"]
    # The CLI's sweep.csv.
    sweep_file = tmp_path / "sweep.toml"
    sweep_file.write_text(
        f'base = "{fast_gear_file}"\nstages = ["ltca", "wear"]\ncycles = 20000\nstep_cycles = 10000\n'
        "[grid]\n" + "".join(f'"{k}" = {json.dumps(v)}\n' for k, v in GRID.items())
    )
    cli("-q", "sweep", sweep_file, "-o", tmp_path / "cli", "--base-anywhere")
    csv = pd.read_csv(tmp_path / "cli" / "sweep.csv")
    assert len(csv) == 6
    for column in RESULT_COLUMNS:
        np.testing.assert_allclose(
            local[column].to_numpy(float), csv[column].to_numpy(float), rtol=1e-15, equal_nan=True
        )
    assert list(csv["ok"]) == [int(x) for x in local["ok"]]
    # A Dask LocalCluster of two worker processes.
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            distributed = wormwear.sweep(
                base, GRID, stages=["ltca", "wear"], cycles=20000, step_cycles=10000, client=client
            )
    pd.testing.assert_frame_equal(rows_of(local), rows_of(distributed))


def test_an_interrupted_sweep_resumes_where_it_stopped(cli, fast_gear_file, tmp_path):
    sweep_file = tmp_path / "sweep.toml"
    sweep_file.write_text(
        f'base = "{fast_gear_file}"\nstages = ["ltca", "wear"]\ncycles = 40000\nstep_cycles = 10000\n'
        '[grid]\n"conditions.worm_torque_nm" = [20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0]\n'
    )
    out = tmp_path / "out"
    process = subprocess.Popen(
        [str(cli_path()), "-q", "sweep", str(sweep_file), "-o", str(out), "--base-anywhere"],
        stderr=subprocess.PIPE,
    )
    deadline = time.time() + 120
    while time.time() < deadline and not list(out.glob("variants/*/variant.json")):
        time.sleep(0.05)
    process.kill()
    process.wait()
    finished = {p.parent.name for p in out.glob("variants/*/variant.json")}
    assert 1 <= len(finished) < 8, finished
    # Resumed from Python into the same directory: the finished variants are reused (their
    # recorded wall time comes back unchanged), the rest run, and the rows equal a fresh run.
    before = pd.read_csv(out / "sweep.csv") if (out / "sweep.csv").exists() else None
    base = wormwear.load(str(fast_gear_file))
    grid = {"conditions.worm_torque_nm": [20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0]}
    resumed = wormwear.sweep(base, grid, stages=["ltca", "wear"], cycles=40000, step_cycles=10000, output=out)
    assert resumed["ok"].all() and len(resumed) == 8
    if before is not None:
        kept = before.set_index("variant")["seconds"]
        now = resumed.set_index("variant")["seconds"]
        for v in finished & set(kept.index):
            assert math.isclose(now[v], kept[v], abs_tol=1e-3), v
    fresh = wormwear.sweep(base, grid, stages=["ltca", "wear"], cycles=40000, step_cycles=10000)
    pd.testing.assert_frame_equal(rows_of(resumed), rows_of(fresh))
    assert (out / "sweep.html").is_file() and (out / "variants" / "v8" / "gear.toml").is_file()


def test_the_gil_is_released_during_a_run(design_file):
    gear = wormwear.load(str(design_file)).with_(**{"bending.model": "none"})
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.005)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    wormwear.run(gear, stages=["ltca"])
    elapsed = time.perf_counter() - start
    done.set()
    t.join()
    during = [x for x in ticks if start < x < start + elapsed]
    # A thread blocked on the GIL would not tick at all during the run.
    assert len(during) > 0.3 * elapsed / 0.005, (len(during), elapsed)


def _stacks_of(p):
    """Python tracebacks of every thread of a hung child (faulthandler on SIGUSR1) and, where
    gdb may attach, its native stacks: what a timeout needs to be diagnosed."""
    native = ""
    if shutil.which("gdb"):
        try:
            native = subprocess.run(
                ["gdb", "-p", str(p.pid), "-batch", "-ex", "thread apply all bt 30"],
                capture_output=True, text=True, timeout=60,
            ).stdout
        except Exception as e:  # noqa: BLE001 - diagnostics only
            native = f"gdb failed: {e}"
    p.send_signal(signal.SIGUSR1)
    time.sleep(1.0)
    p.kill()
    out, err = p.communicate()
    return f"stdout:\n{out}\nstderr (Python stacks):\n{err}\nnative stacks:\n{native}"


def test_ctrl_c_interrupts_a_life(design_file, tmp_path):
    script = (
        "import faulthandler, signal, wormwear, sys\n"
        "faulthandler.register(signal.SIGUSR1, all_threads=True)\n"
        # A shell that runs the suite in the background hands its children SIGINT ignored,
        # and Python then installs no KeyboardInterrupt handler: install it (a user's Ctrl-C
        # reaches an interactive Python that has it).
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        f"g = wormwear.load({str(design_file)!r}).with_(**{{'bending.model': 'none'}})\n"
        "print('start', flush=True)\n"
        "try:\n"
        "    wormwear.run(g, stages=['wear'], cycles=1e7, step_cycles=2000)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n"
        "    sys.exit(7)\n"
    )
    p = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    assert p.stdout.readline().strip() == "start"
    time.sleep(3.0)
    sent = time.time()
    p.send_signal(signal.SIGINT)
    try:
        code = p.wait(timeout=60)
    except subprocess.TimeoutExpired:
        # Once in five CI runs the child did not exit (session 12); the stacks say where it was.
        pytest.fail("no exit within 60 s of SIGINT\n" + _stacks_of(p))
    assert code == 7, p.stdout.read() + p.stderr.read()
    assert time.time() - sent < 30


def test_rexs_stage_loads_and_results_go_back_to_rexs(tmp_path):
    path = ROOT / "examples" / "rexs" / "worm-stage-zi-2x41.rexs"
    assert wormwear.rexs_stages(path) == [
        {"id": 3, "name": "worm stage ZI 2/41", "worm": 10, "wheel": 20}
    ]
    gear = wormwear.load_rexs(path)
    v = gear.validated()
    assert v["worm"]["starts"] == 2 and v["wheel"]["teeth"] == 41
    # tan(gamma) = z1 m_x / d_m1 = 8 / 36 (the worm's lead angle, from the validated gear).
    assert math.isclose(v["worm"]["axial_pitch"], 4e-3 * math.pi, rel_tol=1e-15)
    assert "worm_gear.flank_form" in gear.to_toml()
    # Coarse and without bending: a second's loaded analysis, written back as REXS JSON.
    quick = gear.with_(**{
        "bending.model": "none",
        "analysis.flank_cells_height": 16,
        "analysis.flank_cells_face": 24,
        "analysis.positions": 6,
    })
    r = wormwear.run(quick, stages=["ltca"])
    out = tmp_path / "zi.rexsj"
    r.to_rexs(out)
    text = out.read_text()
    assert "mean_hertzian_stress_ltca_worm_stage" in text
    back, first = wormwear.load_rexs(out).validated(), quick.validated()
    for key in ("axial_pitch", "reference_radius", "tip_radius", "axial_thickness"):
        assert math.isclose(back["worm"][key], first["worm"][key], rel_tol=1e-11), key
    # A placeholder steel wheel warns; a file that is not REXS raises InputError.
    with pytest.warns(UserWarning, match="not a bronze"):
        wormwear.load_rexs(ROOT / "crates/wormwear/tests/data/rexs/zk-1x30-placeholder.rexs")
    bad = tmp_path / "bad.rexs"
    bad.write_text("<model version='1.4'><components>")
    with pytest.raises(wormwear.InputError, match="ends inside"):
        wormwear.load_rexs(bad)


def test_the_readme_session_runs_as_written(tmp_path, monkeypatch):
    # The README's notebook-style session, executed as written from a directory that has the
    # repository's examples (its outputs go to tmp_path/out).
    text = (ROOT / "README.md").read_text()
    start = text.index("```python\nimport wormwear\n") + len("```python\n")
    block = text[start : text.index("```", start)]
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(block, "README.md", "exec"), namespace)
    assert (tmp_path / "out" / "compare" / "compare.html").exists()
    assert (tmp_path / "out" / "zi.rexs").exists()
    assert namespace["same"].to_dict() == namespace["gear"].to_dict()


def test_the_readme_dask_script_runs_as_written(tmp_path):
    # Issue 59: the README's Dask snippet lacked LocalCluster's import, the gear and a
    # __main__ guard. Run as the README says: a script, from the repository root.
    text = (ROOT / "README.md").read_text()
    start = text.index("```python\nfrom dask.distributed") + len("```python\n")
    script = tmp_path / "sweep_on_dask.py"
    script.write_text(text[start : text.index("```", start)])
    done = subprocess.run([sys.executable, str(script)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    for variant in ["v1", "v2", "v3", "v4"]:
        assert variant in done.stdout, done.stdout


def test_step_solids_equal_the_cli_and_bad_requests_raise(cli, design_file, tmp_path):
    # The CLI's --step and the Python run's step=True write the same STEP files.
    cli("-q", "geometry", design_file, "-o", tmp_path / "cli", "--step", "--step-teeth", "3")
    gear = wormwear.load(str(design_file))
    r = wormwear.run(gear, stages=["geometry"], step=True, step_teeth=3)
    r.write(tmp_path / "py")
    for name in ("worm.step", "wheel.step", "cad_faces.csv"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes(), name
    cad = r.summary["cad"]
    assert cad["length_unit"] == "mm" and cad["max_flank_fit_deviation_um"] < 1.0
    assert cad["wheel_worn"] is None
    faces = pd.read_csv(tmp_path / "py" / "cad_faces.csv")
    assert set(faces["part"]) == {"worm", "wheel"}
    with pytest.raises(wormwear.InputError, match="allowed 1 to 40"):
        wormwear.run(gear, stages=["geometry"], step=True, step_teeth=0)
    with pytest.raises(wormwear.InputError, match="needs a life"):
        wormwear.run(gear, stages=["geometry"], step=True, step_state=2)


def test_arguments_of_the_wrong_kind_are_refused_naming_the_argument(design_file, tmp_path):
    # Issue 58: run("file.toml") raised AttributeError, stages="ltca" and compare("a", "b")
    # iterated the strings' characters, step_teeth=-1 an OverflowError, NaN in with_ a JSON
    # parser's "expected value at line 1 column 31", step_wear_um with step_cycles passed.
    gear = wormwear.load(str(design_file))
    with pytest.raises(TypeError, match="run: gear must be a wormwear.GearSet"):
        wormwear.run(str(design_file))
    with pytest.raises(TypeError, match="stages must be a list"):
        wormwear.run(gear, stages="ltca")
    with pytest.raises(ValueError, match="step_teeth"):
        wormwear.run(gear, step=True, step_teeth=-1)
    with pytest.raises(ValueError, match="exclude each other"):
        wormwear.run(gear, ["wear"], cycles=20000, step_cycles=10000, step_wear_um=4.0)
    with pytest.raises(TypeError, match="compare: runs must be a list"):
        wormwear.compare("a", tmp_path / "out")
    with pytest.raises(wormwear.InputError, match=r"with_\(conditions.worm_torque_nm\): nan"):
        gear.with_(**{"conditions.worm_torque_nm": float("nan")})


def test_a_duty_cycle_equals_the_cli(cli, tmp_path):
    # MODEL §14: the spectrum's section and its bins' table, in numbers and files; without
    # bending and on a coarse grid to be quick.
    g = wormwear.load(EXAMPLES / "gear-1x40-duty-cycle.toml").with_(
        **{"bending.model": "none", "analysis.positions": 8,
           "analysis.flank_cells_height": 20, "analysis.flank_cells_face": 30}
    )
    path = tmp_path / "duty.toml"
    path.write_text(g.to_toml())
    cli("-q", "ltca", path, "-o", tmp_path / "cli")
    r = wormwear.run(g, stages=["ltca"])
    written = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert_close(r.summary["duty_cycle"], written["duty_cycle"])
    bins = r.duty_cycle.bins
    file = pd.read_csv(tmp_path / "cli" / "duty_cycle.csv")
    assert list(bins.columns) == list(file.columns) and len(bins) == 3
    np.testing.assert_allclose(bins.to_numpy(float), file.to_numpy(float), rtol=6e-11, atol=0)
    assert list(bins["bin"]) == [1, 2, 3]
    assert bins["cycle_share"].sum() == pytest.approx(1.0, abs=1e-12)
    assert r.duty_cycle.largest_load_bin == 3
    # One operating point has no duty cycle.
    assert wormwear.run(wormwear.load(EXAMPLES / "gear-1x40-design.toml").with_(
        **{"bending.model": "none", "analysis.positions": 8}), stages=["ltca"]).duty_cycle is None


def test_a_spread_equals_the_cli_and_bad_inputs_raise_naming_the_field(cli, fast_gear_file, tmp_path):
    base = wormwear.load(str(fast_gear_file))
    inputs = {
        "operating.worm_offset_mm": (-0.05, 0.05),
        "conditions.worm_torque_nm": {"mean": 60.0, "sd": 5.0, "min": 50.0, "max": 70.0},
    }
    result = wormwear.spread(base, inputs, samples=4, seed=3, output=tmp_path / "py")
    assert len(result.samples) == 4 and result.samples["ok"].all()
    assert set(result.rank_correlation.columns) == set(inputs)
    assert result.sobol_indices is None
    assert (tmp_path / "py" / "spread.html").is_file()
    # The CLI on the same spread file: the same samples and results to the bit.
    spread_file = fast_gear_file.parent / "spread.toml"
    spread_file.write_text(
        f'base = "{fast_gear_file.name}"\n[spread]\nsamples = 4\nseed = 3\n[spread.inputs]\n'
        '"operating.worm_offset_mm" = [-0.05, 0.05]\n'
        '"conditions.worm_torque_nm" = { mean = 60.0, sd = 5.0, min = 50.0, max = 70.0 }\n'
    )
    cli("-q", "spread", spread_file, "-o", tmp_path / "cli")
    assert (tmp_path / "cli" / "spread.csv").read_bytes() == (tmp_path / "py" / "spread.csv").read_bytes()
    cli_summary = json.loads((tmp_path / "cli" / "spread.json").read_text())
    assert cli_summary["results"] == result.summary["results"]
    # On a Dask LocalCluster of two worker processes: the same samples and results.
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            on_dask = wormwear.spread(base, inputs, samples=4, seed=3, output=tmp_path / "dask", client=client)
    assert on_dask.reused == 4 and result.reused == 0
    assert (tmp_path / "dask" / "spread.csv").read_bytes() == (tmp_path / "py" / "spread.csv").read_bytes()
    # The Sobol sampler: samples x (inputs + 2) runs and each result's indices.
    sobol = wormwear.spread(
        base, {"conditions.worm_torque_nm": (50.0, 70.0)}, samples=2, sampler="sobol", output=tmp_path / "sobol"
    )
    assert len(sobol.samples) == 6
    efficiency = sobol.sobol_indices.set_index("result").loc["mesh_efficiency"]
    assert efficiency["input"] == "conditions.worm_torque_nm" and np.isfinite(efficiency["total"])
    # The root stress's kept sector can be let go; a spread after it gives the same results.
    wormwear.forget_kept_sector()
    again = wormwear.spread(base, inputs, samples=4, seed=3, output=tmp_path / "again")
    assert (tmp_path / "again" / "spread.csv").read_bytes() == (tmp_path / "py" / "spread.csv").read_bytes()
    # Bad input: the field named, with the nearest names.
    with pytest.raises(wormwear.InputError, match="operating.centre_distance_error_mm"):
        wormwear.spread(base, {"operating.centre_distance_eror_mm": (0.0, 0.01)}, output=tmp_path / "bad")
    with pytest.raises(wormwear.InputError, match="inverted range"):
        wormwear.spread(base, {"operating.worm_offset_mm": (0.05, -0.05)}, output=tmp_path / "bad")


def test_the_pattern_assistant_equals_the_cli_and_bad_inputs_raise_naming_them(cli, design_file, tmp_path):
    base = wormwear.load(design_file)
    target = {"centre_across_face": 0.6}
    vary = {"cutting.inclination_deg": (-0.3, 0.3)}
    found = wormwear.pattern(base, target, vary=vary, evaluations=6, output=tmp_path / "py")
    assert list(found.settings["name"]) == ["cutting.inclination_deg"]
    assert found.objective["best"] <= found.objective["start"]
    assert len(found.path) == found.summary["evaluations"] <= 6
    assert abs(found.after["centre_across_face"] - 0.6) <= abs(found.before["centre_across_face"] - 0.6)
    assert found.gear.validated()["cutting"]["inclination"] == pytest.approx(
        math.radians(found.settings["best"][0]), abs=1e-12
    )
    # The CLI on the same gear and target: the same search, the same best gear file.
    cli("-q", "pattern", design_file, "--target", "centre_across_face=0.6", "--vary",
        "cutting.inclination_deg=-0.3:0.3", "--evaluations", "6", "-o", tmp_path / "cli")
    assert (tmp_path / "cli" / "search.csv").read_bytes() == (tmp_path / "py" / "search.csv").read_bytes()
    with pytest.raises(wormwear.InputError, match="centre_across_face"):
        wormwear.pattern(base, {"centre": 0.6}, output=tmp_path / "bad")
    with pytest.raises(wormwear.InputError, match="cutting.centre_distance_mm"):
        wormwear.pattern(base, target, vary={"cutting.centre_distanse_mm": (124.5, 125.5)}, output=tmp_path / "bad")


def test_the_running_in_of_the_roughness_reaches_the_records_and_maps(fast_gear_file, tmp_path):
    # MODEL §6.1: with lubricant.run_in_roughness_um and running_in_depth_um the worn flank's
    # roughness falls (records, map); running in to the initial roughness is the published life.
    base = wormwear.load(str(fast_gear_file))
    run_in = base.with_(**{"lubricant.run_in_roughness_um": 0.5,
                           "lubricant.running_in_depth_um": 2.0})
    r = wormwear.run(run_in, ["wear"], cycles=40000, step_cycles=20000)
    records = r.wear.records
    assert records["roughness_mean_m"].iloc[0] == 1e-6 and records["roughness_min_m"].iloc[0] == 1e-6
    assert 0.5e-6 <= records["roughness_min_m"].iloc[-1] < records["roughness_mean_m"].iloc[-1] < 1e-6
    r.write(tmp_path / "run-in")
    assert (tmp_path / "run-in" / "wear_roughness_map.svg").exists()
    same = base.with_(**{"lubricant.run_in_roughness_um": 1.0,
                         "lubricant.running_in_depth_um": 2.0})
    published = wormwear.run(base, ["wear"], cycles=40000, step_cycles=20000).wear.records
    limit = wormwear.run(same, ["wear"], cycles=40000, step_cycles=20000).wear.records
    pd.testing.assert_frame_equal(published, limit)
    with pytest.raises(wormwear.InputError, match="lubricant.run_in_roughness_um"):
        base.with_(**{"lubricant.run_in_roughness_um": 2.0, "lubricant.running_in_depth_um": 2.0})
