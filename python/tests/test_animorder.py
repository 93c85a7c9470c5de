"""The Python module against the CLI (the same bytes for the same input and settings, the same
OVR from the same evaluation), hand-worked cases, and bad input. CTest runs it with
scripts/test-python.sh: PYTHONPATH holds the built module, ANIMORDER_EXE names the CLI."""
import json
import os
import subprocess
import threading

import numpy as np
import pytest

import animorder

CLI = os.environ["ANIMORDER_EXE"]
FAST = dict(clusters=2, views=12, resolution=32, max_iterations=2)
FAST_ARGS = ["-k", "2", "--views", "12", "--resolution", "32", "--max-iterations", "2"]


def cli(*args):
    done = subprocess.run([CLI, *args], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def same_files(a, b):
    with open(a, "rb") as x, open(b, "rb") as y:
        return x.read() == y.read()


@pytest.mark.parametrize("method", ["single", "measured", "static-sander07"])
def test_bundled_character_gives_the_clis_bytes(tmp_path, method):
    character = animorder.bundled_character()
    result = animorder.run(character, method, **FAST)
    (tmp_path / "py").mkdir()
    (tmp_path / "cli").mkdir()
    animorder.write_sidecar(character, result, str(tmp_path / "py" / "out"))
    cli("optimize", "-q", "--method", method, *FAST_ARGS, "-o", str(tmp_path / "cli" / "out"))
    for name in ["out.animorder.bin", "out.animorder.json"]:
        assert same_files(tmp_path / "py" / name, tmp_path / "cli" / name), name
    assert result.method == method


def test_default_method_is_the_clis():
    assert animorder.run.__doc__ is not None
    character = animorder.bundled_character()
    assert animorder.run(character, **FAST).method == "measured"


def test_a_gltf_file_loads_runs_and_writes_the_clis_gltf(tmp_path):
    glb = tmp_path / "walk.glb"
    cli("subdivide", "-q", "--levels", "0", "--clip", "walk", "-o", str(glb))
    character = animorder.load(str(glb))
    assert character.clips == [("walk", character.keyframes)]
    result = animorder.run(character, "single", lambda_=3, **FAST)
    (tmp_path / "py").mkdir()
    (tmp_path / "cli").mkdir()
    animorder.write_gltf(character, result, str(tmp_path / "py" / "out.glb"))
    animorder.write_sidecar(character, result, str(tmp_path / "py" / "out"))
    cli("optimize", str(glb), "-q", "--method", "single", "--lambda", "3", *FAST_ARGS, "-o", str(tmp_path / "cli" / "out.glb"))
    for name in ["out.glb", "out.animorder.bin", "out.animorder.json"]:
        assert same_files(tmp_path / "py" / name, tmp_path / "cli" / name), name


VARYING = {"time_s", "timings_s", "stages_s", "peak_rss_bytes", "settings", "outputs"}


def steady(value):
    """A report without what varies run to run (times, memory) or is the CLI's alone."""
    if isinstance(value, dict):
        return {k: steady(v) for k, v in value.items() if k not in VARYING and not k.startswith("seconds")}
    if isinstance(value, list):
        return [steady(v) for v in value]
    return value


def test_orders_tables_and_the_clis_report(tmp_path):
    character = animorder.bundled_character()
    result = animorder.run(character, "single", **FAST)
    entry = result.report["methods"][0]
    assert len(result.orders) == entry["buffers"] == 2 * len(character.clips)
    for order in result.orders:
        assert order.dtype == np.uint32
        assert sorted(order.tolist()) == list(range(character.triangles))  # a face permutation
    assert len(result.tables) == len(character.clips)
    for (name, keyframes), table in zip(character.clips, result.tables):
        assert table.shape == (keyframes, 37, 72)
        assert table.max() < 2  # a cell names one of the clip's k = 2 buffers
    assert 0.5 < result.acmr < 1.2
    report = tmp_path / "r.json"
    cli("optimize", "-q", "--method", "single", *FAST_ARGS, "--report", str(report))
    assert steady(result.report) == steady(json.loads(report.read_text()))


def test_evaluation_is_the_clis(tmp_path):
    character = animorder.bundled_character()
    results = [animorder.run(character, m, **FAST) for m in ["original", "single"]]
    ours = animorder.evaluate(character, results, views=4, resolution=64)
    report = tmp_path / "r.json"
    cli("evaluate", "-q", "--methods", "original,single", *FAST_ARGS, "--eval-views", "4", "--eval-resolution", "64",
        "-r", str(report))
    theirs = json.loads(report.read_text())["methods"]
    assert [m["name"] for m in ours["methods"]] == [m["name"] for m in theirs]
    for a, b in zip(ours["methods"], theirs):
        assert a["ovr_mean"] == b["ovr_mean"]
        assert a["ovr_pooled"] == b["ovr_pooled"]


def test_arrays_a_hand_worked_triangle():
    # One triangle facing +z, two keyframes, two clips of one keyframe each.
    positions = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 0], [2, 0, 0], [0, 2, 0]]], dtype=np.float32)
    character = animorder.from_arrays(positions, np.array([[0, 1, 2]]), clips=[("a", 1), ("b", 1)])
    assert (character.triangles, character.vertices, character.keyframes) == (1, 3, 2)
    assert animorder.run(character, "original").report["input"] == "arrays"
    assert character.clips == [("a", 1), ("b", 1)]
    assert np.array_equal(character.positions, positions)
    result = animorder.run(character, "original")
    assert [o.tolist() for o in result.orders] == [[0]]
    # One triangle: every pixel it covers is shaded once, whatever the view.
    ovr = animorder.evaluate(character, [result], views=8, resolution=32)["methods"][0]
    assert ovr["ovr_mean"] == 1.0 and ovr["ovr_pooled"] == 1.0


def test_long_work_releases_the_gil_and_reports_progress():
    character = animorder.bundled_character()
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            stop.wait(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    try:
        animorder.run(character, "single", clusters=2, views=42, resolution=64)  # no callback: no Python runs
    finally:
        stop.set()
        counter.join()
    assert len(ticks) > 10  # the other thread ran while the method did
    stages = []
    animorder.run(character, "single", progress=lambda stage, done, total: stages.append((stage, done, total)), **FAST)
    assert stages and all(0 <= done <= total for _, done, total in stages)
    assert any("rasterising nodes" in stage for stage, _, _ in stages), stages


def test_an_exception_in_progress_ends_the_run():
    def fail(stage, done, total):
        raise KeyboardInterrupt("stop")

    with pytest.raises(KeyboardInterrupt):
        animorder.run(animorder.bundled_character(), "single", progress=fail, **FAST)


def test_bad_input_is_an_exception_with_the_librarys_message(tmp_path):
    character = animorder.bundled_character()
    with pytest.raises(ValueError, match="unknown method|not a method|method"):
        animorder.run(character, "fastest")
    with pytest.raises(ValueError, match="unknown setting 'clusterz'"):
        animorder.run(character, "single", clusterz=3)
    with pytest.raises(ValueError, match="k \\(clusters\\) must be between 1 and"):
        animorder.run(character, "single", clusters=0)
    with pytest.raises(ValueError, match="resolution"):
        animorder.run(character, "single", resolution=4)
    with pytest.raises(ValueError, match="setting 'clusters': -1 is not a whole number"):
        animorder.run(character, "single", clusters=-1)
    with pytest.raises(ValueError, match="setting 'lambda_': 'x' is not a number"):
        animorder.run(character, "single", lambda_="x")
    with pytest.raises(ValueError, match="lambda must be between 0 and 1000"):
        animorder.run(character, "single", lambda_=2000)
    original = animorder.run(character, "original")
    with pytest.raises(ValueError, match="results\\[1\\] is None"):
        animorder.evaluate(character, [original, None], views=1, resolution=16)
    with pytest.raises(ValueError, match="views must be between 1 and 100000"):
        animorder.evaluate(character, [original], views=0)
    # A result of another character is refused, not read past its triangles.
    small = animorder.from_arrays(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], dtype=np.float32), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="this result was run on a character of 11760 triangles"):
        animorder.write_sidecar(small, original, str(tmp_path / "small"))
    with pytest.raises(ValueError, match="this result was run on a character of"):
        animorder.evaluate(small, [original], views=1, resolution=16)
    with pytest.raises(OSError):
        animorder.write_sidecar(character, original, str(tmp_path / "no such folder" / "out"))
    with pytest.raises(OSError, match="missing.glb"):
        animorder.load(str(tmp_path / "missing.glb"))
    truncated = tmp_path / "truncated.glb"
    truncated.write_bytes(b"glTF\x02\x00\x00\x00\xff\xff\x00\x00")
    with pytest.raises(OSError, match="truncated.glb"):
        animorder.load(str(truncated))
    triangle = np.zeros((1, 3, 3), dtype=np.float32)
    with pytest.raises(ValueError, match="index|vertex|out of range|outside"):
        animorder.from_arrays(triangle, np.array([[0, 1, 7]]))
    nan = np.array([[[0, 0, 0], [1, 0, 0], [0, np.nan, 0]]], dtype=np.float32)
    with pytest.raises(ValueError, match="NaN|finite|not a number"):
        animorder.from_arrays(nan, np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="shape"):
        animorder.from_arrays(np.zeros((3, 3), dtype=np.float32), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="keyframes"):
        animorder.from_arrays(np.zeros((2, 3, 3), dtype=np.float32), np.array([[0, 1, 2]]), clips=[("a", 3)])
    with pytest.raises(ValueError, match="write_gltf needs a character loaded from a glTF file"):
        animorder.write_gltf(character, animorder.run(character, "original"), str(tmp_path / "x.glb"))
    # Nothing the user gave is overwritten: the glTF input itself as the output.
    glb = tmp_path / "walk.glb"
    cli("subdivide", "-q", "--levels", "0", "--clip", "walk", "-o", str(glb))
    before = glb.read_bytes()
    with pytest.raises((ValueError, OSError), match="no such clip"):
        animorder.load(str(glb), clips=["no such clip"])
    loaded = animorder.load(str(glb))
    with pytest.raises(ValueError, match="is the input"):
        animorder.write_gltf(loaded, animorder.run(loaded, "original"), str(glb))
    assert glb.read_bytes() == before


def test_version_is_the_packages():
    assert cli("--version").stdout.strip() == "animorder " + animorder.__version__


def test_the_readmes_python_block_runs_as_written(tmp_path, monkeypatch):
    readme = open(os.path.join(os.path.dirname(__file__), "..", "..", "README.md"), encoding="utf-8").read()
    start = readme.index("```python\n") + len("```python\n")
    block = readme[start:readme.index("```", start)]
    cli("subdivide", "-q", "--levels", "0", "-o", str(tmp_path / "character.glb"))
    monkeypatch.chdir(tmp_path)
    scope = {}
    exec(compile(block, "README.md", "exec"), scope)
    assert scope["result"].method == "measured"
    assert sorted(scope["first"].tolist()) == list(range(scope["character"].triangles))
    assert 1.0 <= scope["ovr"] < 2.0
    assert (tmp_path / "character.animorder.bin").stat().st_size > 0
    assert (tmp_path / "character.animorder.json").stat().st_size > 0
