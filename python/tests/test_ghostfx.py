"""pytest suite of the ghostfx Python module (run by ctest as `python.pytest`).

Each test states where its bound comes from. The module is the same code as the command line, so
the error texts are compared with the command line's own."""
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import ghostfx

SOURCE = os.environ.get("GHOSTFX_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("GHOSTFX_EXE")
DAM = os.path.join(SOURCE, "examples", "dam_break", "scene.json")


def test_load_scene_with_overrides():
    scene = ghostfx.load_scene(DAM, {"settings.frame_range": [1, 2], "settings.stiffness": 5000})
    assert scene.method == "ghost"
    assert scene.frame_range == (1, 2)
    assert scene.spacing == pytest.approx(0.015)


def test_scene_errors_raise_value_error_with_the_command_lines_text():
    with pytest.raises(ValueError) as error:
        ghostfx.load_scene(DAM, {"settings.spacing": -1})
    text = str(error.value)
    assert text == f"scene '{DAM}': settings.spacing = -1: expected a number > 0"
    if EXE:  # the same line as `ghostfx run`, after its "ghostfx: error: " prefix
        run = subprocess.run([EXE, "run", DAM, "-D", "settings.spacing=-1", "--out", "/nonexistent/x"],
                             capture_output=True, text=True)
        assert run.returncode == 1
        assert run.stderr.strip() == "ghostfx: error: " + text
    with pytest.raises(ValueError, match="unknown key"):
        ghostfx.load_scene(DAM, {"settings.stifness": 5000})
    # A file that cannot be read is an OSError, as for open().
    with pytest.raises(OSError, match="cannot open the file"):
        ghostfx.load_scene(os.path.join(SOURCE, "no_such_scene.json"))


def test_one_frame_of_the_dam_break_falls_and_arrays_are_well_formed():
    scene = ghostfx.load_scene(DAM, {"settings.frame_range": [1, 1]})
    sim = ghostfx.Simulation(scene)
    start = sim.positions("liquid")
    assert start.dtype == np.float64 and start.ndim == 2 and start.shape[1] == 3
    sim.run()
    assert sim.frame == 1 and sim.time == pytest.approx(1 / 30)
    x = sim.positions("liquid")
    v = sim.velocities("liquid")
    assert x.shape == start.shape == v.shape  # a closed tank: no liquid enters or leaves
    assert np.isfinite(x).all() and np.isfinite(v).all()
    assert f"{x.shape[0]} liquid" in sim.counts
    # The column starts to collapse: its centre of mass drops, by less than free fall
    # g t^2 / 2 = 5.45 mm in 1/30 s (the floor and the pressure hold it up).
    drop = start[:, 1].mean() - x[:, 1].mean()
    free_fall = 0.5 * 9.81 * (1 / 30) ** 2
    assert 0 < drop < free_fall
    # Ghost solids and air are there and reported apart.
    assert sim.positions("solid").shape[0] > 0
    assert sim.positions("air").shape[0] > 0
    ids = sim.channel("liquid", "id")
    assert ids.dtype == np.int64 and len(np.unique(ids)) == x.shape[0]
    density = sim.channel("liquid", "density")
    # Liquid at about rest density ([SB12] soft k: within 10 % of 1000 kg/m^3 on average).
    assert density.mean() == pytest.approx(1000, rel=0.1)
    with pytest.raises(ValueError, match="particle kind 'water'"):
        sim.positions("water")


def test_run_calls_back_after_every_frame():
    sim = ghostfx.Simulation(ghostfx.load_scene(DAM, {"settings.frame_range": [1, 2]}))
    seen = []
    sim.run(on_frame=lambda s: seen.append((s.frame, s.steps)))
    assert [f for f, _ in seen] == [1, 2]
    assert seen[0][1] < seen[1][1]


@pytest.mark.skipif(not EXE, reason="needs the ghostfx program to make a level set")
def test_sample_a_level_set_from_a_vdb(tmp_path):
    # A 0.1 m cube as an OBJ mesh, to a level set with the command line's mesh2sdf.
    corners = [(x, y, z) for x in (0, 0.1) for y in (0, 0.1) for z in (0, 0.1)]
    faces = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    obj = tmp_path / "cube.obj"
    obj.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in corners)
                   + "".join(f"f {a} {b} {c}\nf {a} {c} {d}\n" for a, b, c, d in faces))
    vdb = tmp_path / "cube.vdb"
    subprocess.run([EXE, "mesh2sdf", str(obj), "-o", str(vdb), "--voxel-size", "0.005"], check=True,
                   capture_output=True)
    spacing = 0.01
    samples = ghostfx.sample(str(vdb), "surface", spacing)
    assert samples.shape[1] == 3
    # The samples fill the cube: count close to its volume over spacing^3 (1000) within the
    # sampler's packing ([SB12] Poisson radius 0.92 h: the sampler's own tests measure 1.0-1.3x).
    assert 800 < samples.shape[0] < 1500
    assert samples.min() > -0.005 and samples.max() < 0.105
    with pytest.raises(ValueError, match="grid 'nope'"):
        ghostfx.sample(str(vdb), "nope", spacing)


def resumed_and_straight(scene, stop, checkpoint):
    """The scene run to its last frame straight, and the same run checkpointed after frame
    `stop` (to `checkpoint`) and resumed from it."""
    straight = ghostfx.Simulation(scene)
    straight.run()
    first = ghostfx.Simulation(scene)
    first.run(frames=stop)
    first.save_checkpoint(checkpoint)
    resumed = ghostfx.Simulation.resume(scene, checkpoint)
    assert resumed.frame == stop
    resumed.run()
    assert resumed.frame == straight.frame == scene.frame_range[1]
    return resumed, straight


def assert_same_particles(a, b, kinds):
    for kind in kinds:
        assert np.array_equal(a.positions(kind), b.positions(kind)), kind
        assert np.array_equal(a.velocities(kind), b.velocities(kind)), kind


def test_resume_from_a_checkpoint_matches_an_uninterrupted_run_bit_for_bit(tmp_path):
    scene = ghostfx.load_scene(DAM, {"settings.frame_range": [1, 3]})
    checkpoint = str(tmp_path / "dam.0001.h5")
    resumed, straight = resumed_and_straight(scene, 1, checkpoint)
    assert_same_particles(resumed, straight, ("liquid", "air"))
    # A checkpoint of other settings is refused, naming the key and both values.
    stiffer = ghostfx.load_scene(DAM, {"settings.frame_range": [1, 3], "settings.stiffness": 3000})
    with pytest.raises(ValueError, match="stiffness"):
        ghostfx.Simulation.resume(stiffer, checkpoint)


def test_no_leak_over_a_thousand_calls():
    # 1,000 array copies and 20 scene loads: the process grows by less than 20 MB (each copy of the
    # liquid positions is 106 kB; a leak of every copy alone would be 106 MB).
    import resource
    sim = ghostfx.Simulation(ghostfx.load_scene(DAM, {"settings.frame_range": [1, 1]}))
    for _ in range(50):
        sim.positions("liquid")
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for _ in range(1000):
        sim.positions("liquid")
        sim.channel("liquid", "density")
    for _ in range(20):
        ghostfx.load_scene(DAM)
    grown_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown_kb < 20_000


def test_ctrl_c_stops_at_the_end_of_a_frame(tmp_path):
    # A script runs 200 frames; SIGINT arrives during the run. It must end with
    # KeyboardInterrupt after a whole frame (the state is at a frame boundary), not mid-step.
    script = tmp_path / "run.py"
    script.write_text(f"""
import sys, ghostfx
sim = ghostfx.Simulation(ghostfx.load_scene({DAM!r}, {{"settings.frame_range": [1, 200]}}))
print("ready", flush=True)
try:
    sim.run()
except KeyboardInterrupt:
    print("interrupted", sim.frame, abs(sim.time * 30 - sim.frame) < 1e-9, flush=True)
    sys.exit(3)
""")
    import signal
    import time
    child = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True,
                             env=dict(os.environ))
    assert child.stdout.readline().strip() == "ready"
    time.sleep(1.5)
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    assert child.returncode == 3, out
    word, frame, at_boundary = out.split()
    assert word == "interrupted" and 1 <= int(frame) < 200 and at_boundary == "True"


@pytest.mark.parametrize("name", ["SIGTERM", "SIGUSR1"])
def test_a_farms_stop_signal_writes_the_frames_checkpoint_and_exits_with_its_code(tmp_path, name):
    # A render farm sends SIGTERM (or Slurm's --signal=USR1) before it pre-empts a job. The
    # script's run() must finish the frame, call on_frame for it, write the checkpoint it was
    # given and end the script with 128 + the signal, as `ghostfx run` does; the checkpoint then
    # resumes the run.
    import signal
    import time
    number = int(getattr(signal, name))
    script = tmp_path / "run.py"
    script.write_text(f"""
import ghostfx
sim = ghostfx.Simulation(ghostfx.load_scene({DAM!r}, {{"settings.frame_range": [1, 400]}}))
print("ready", flush=True)
sim.run(on_frame=lambda s: print("frame", s.frame, flush=True),
        checkpoint={str(tmp_path / "state.$F4.h5")!r})
""")
    child = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    assert child.stdout.readline().strip() == "ready"
    assert child.stdout.readline().startswith("frame")
    time.sleep(0.3)
    child.send_signal(number)
    out, err = child.communicate(timeout=120)
    assert child.returncode == 128 + number, err
    last = int(out.split()[-1])
    checkpoint = tmp_path / f"state.{last:04d}.h5"
    assert checkpoint.exists(), (out, err)
    assert f"ghostfx: stopped by {name} after frame {last}" in err
    resumed = ghostfx.Simulation.resume(ghostfx.load_scene(DAM), str(checkpoint))
    assert resumed.frame == last


def test_a_boiling_scene_checkpoints_and_resumes_bit_for_bit(tmp_path):
    # The liquid, its vapour and the phase transition's counters are all in the checkpoint: the
    # resumed pan equals the uninterrupted one particle for particle.
    scene = ghostfx.load_scene(os.path.join(SOURCE, "examples", "boiling_pan", "scene.json"),
                               {"settings.spacing": 0.03, "settings.frame_range": [1, 4]})
    resumed, straight = resumed_and_straight(scene, 2, str(tmp_path / "pan.0002.h5"))
    assert len(straight.positions("gas")) > 0
    assert_same_particles(resumed, straight, ("liquid", "gas"))
    assert np.array_equal(resumed.channel("liquid", "temperature"),
                          straight.channel("liquid", "temperature"))


def test_write_frame_writes_the_files_the_command_line_writes(tmp_path):
    scene = ghostfx.load_scene(DAM, {"settings.frame_range": [1, 1], "outputs.preview": False})
    sim = ghostfx.Simulation(scene)
    sim.advance_frame()
    sim.write_frame(str(tmp_path))
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["liquid.0001.vdb", "liquid_points.0001.vdb"]
    assert all((tmp_path / n).stat().st_size > 1000 for n in names)
    if EXE:  # `ghostfx info` reads them: the points file holds the liquid particles
        info = subprocess.run([EXE, "info", str(tmp_path / "liquid_points.0001.vdb")],
                              capture_output=True, text=True, check=True).stdout
        assert str(sim.positions("liquid").shape[0]) in info


def test_level_set_from_an_sdf_array_round_trips_and_samples():
    # A sphere of radius 0.05 m on a 5 mm grid, as a dense signed-distance array.
    voxel, radius, n = 0.005, 0.05, 30
    origin = np.array([-0.075, -0.075, -0.075])
    idx = np.indices((n, n, n)).transpose(1, 2, 3, 0)
    points = origin + voxel * idx
    sdf = np.linalg.norm(points, axis=-1) - radius
    shape = ghostfx.LevelSet.from_array(sdf, voxel, tuple(origin), "ball")
    assert shape.name == "ball" and shape.voxel_size == pytest.approx(voxel)
    # phi at grid points within the band is the array's value (float32 storage: 1e-7 m).
    band = np.abs(sdf) < 2 * voxel
    got = shape.phi(points[band].reshape(-1, 3))
    assert np.allclose(got, sdf[band], atol=1e-6)
    # Between grid points, trilinear interpolation of a sphere's distance is within
    # h^2 / 8 * (2 / rho) of it (the bound of tests/sph/test_level_set.cc): 1.6e-4 m at rho 0.04 m.
    rng = np.random.default_rng(3)
    directions = rng.normal(size=(200, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    q = directions * rng.uniform(0.045, 0.055, size=(200, 1))
    assert np.abs(shape.phi(q) - (np.linalg.norm(q, axis=1) - radius)).max() < voxel**2 / 8 * 2 / 0.04 + 1e-6
    # Back to an array: the band values come back exactly.
    values, corner = shape.to_array()
    assert values.dtype == np.float32
    i0 = np.rint((np.array(corner) - origin) / voxel).astype(int)
    sub = sdf[i0[0]:i0[0] + values.shape[0], i0[1]:i0[1] + values.shape[1], i0[2]:i0[2] + values.shape[2]]
    inband = np.abs(sub) < 3 * voxel
    assert np.allclose(values[inband], sub[inband], atol=1e-6)
    # Poisson-disk samples fill it: volume / spacing^3 = 524 at 1 cm, within the sampler's packing.
    samples = ghostfx.sample(shape, 0.01)
    assert 400 < samples.shape[0] < 800
    assert (np.linalg.norm(samples, axis=1) < radius + 1e-3).all()
    with pytest.raises(ValueError, match="expected a 3-D array"):
        ghostfx.LevelSet.from_array(np.zeros((4, 4)), voxel)


def test_a_script_steers_a_moving_solid(tmp_path):
    # A paddle (moving solid: it has a velocity in the scene) pushed into the water by the
    # script at 0.5 m/s from frame 2 on; the liquid in front of it is pushed away.
    import json
    scene = {
        "ghostfx_scene": 1,
        "settings": {"method": "ghost", "spacing": 0.02, "substeps": 0, "frame_range": [1, 4], "seed": 3},
        "solids": [
            {"name": "tank", "geometry": {"container": {"min": [0, 0, 0], "max": [0.6, 0.3, 0.2]}}},
            {"name": "paddle", "geometry": {"box": {"min": [0.02, 0.0, 0.0], "max": [0.08, 0.25, 0.2]}},
             "velocity": [1e-9, 0, 0]},
        ],
        "liquids": [{"name": "water", "geometry": {"box": {"min": [0.1, 0, 0], "max": [0.6, 0.12, 0.2]}}}],
    }
    path = tmp_path / "paddle.json"
    path.write_text(json.dumps(scene))
    sim = ghostfx.Simulation(ghostfx.load_scene(str(path)))
    sim.advance_frame()
    near = lambda x: (x[:, 0] < 0.2).sum()
    before = near(sim.positions("liquid"))
    def paddle_face():  # the paddle's ghosts: above the water, between the side walls
        x = sim.positions("solid")
        inside = (x[:, 0] > 0) & (x[:, 0] < 0.3) & (x[:, 1] > 0.15) & (x[:, 1] < 0.25)
        inside &= (x[:, 2] > 0.01) & (x[:, 2] < 0.19)
        return x[inside, 0].max()

    face0 = paddle_face()
    sim.set_solid_velocity("paddle", (0.5, 0, 0))
    sim.run(frames=3)
    # 3 frames (0.1 s) at 0.5 m/s: the paddle's ghosts move 5 cm with it (to rounding), and fewer
    # liquid particles remain in the first 0.2 m.
    assert paddle_face() - face0 == pytest.approx(0.05, abs=1e-4)
    assert near(sim.positions("liquid")) < before
    with pytest.raises(ValueError, match="static solid"):
        sim.set_solid_velocity("tank", (0.1, 0, 0))
    with pytest.raises(ValueError, match="no such solid"):
        sim.set_solid_velocity("lid", (0.1, 0, 0))


def test_statistics_per_step_as_numpy_arrays():
    sim = ghostfx.Simulation(ghostfx.load_scene(DAM, {"settings.frame_range": [1, 2]}))
    sim.run()
    stats = sim.statistics()
    # One entry per step, the columns of the run command's stats file.
    for name in ("step", "time", "dt", "count_liquid"):
        assert name in stats, sorted(stats)
        assert stats[name].shape == (sim.steps,)
    # Steps are numbered in order and their dt add up to the simulated time (2 frames).
    assert np.all(np.diff(stats["step"]) == 1)
    assert stats["dt"].sum() == pytest.approx(2 / 30, rel=1e-6)
    assert np.all(stats["count_liquid"] == sim.positions("liquid").shape[0])


def test_scene_from_a_dict_and_bodies_added_from_level_sets(tmp_path):
    scene = ghostfx.load_scene({
        "ghostfx_scene": 1,
        "settings": {"method": "ghost", "spacing": 0.02, "substeps": 0, "frame_range": [1, 10], "seed": 2},
        "liquids": [{"name": "drop", "geometry": {"sphere": {"center": [0, 0.2, 0], "radius": 0.05}}}],
    }, folder=tmp_path)
    assert scene.spacing == pytest.approx(0.02)
    assert not list(tmp_path.iterdir())  # the temporary file is gone
    sim = ghostfx.Simulation(scene)
    # A floor slab and a second drop, both from NumPy signed-distance arrays.
    voxel = 0.01
    idx = np.indices((40, 10, 40)).transpose(1, 2, 3, 0)
    origin = np.array([-0.2, -0.1, -0.2])
    pts = origin + voxel * idx
    slab = np.maximum.reduce([np.abs(pts[..., 0]) - 0.15, np.abs(pts[..., 1] + 0.05) - 0.03,
                              np.abs(pts[..., 2]) - 0.15])
    floor = ghostfx.LevelSet.from_array(slab, voxel, tuple(origin), "floor")
    sim.add_solid(floor)
    drop2 = ghostfx.LevelSet.from_array(
        np.linalg.norm(origin + voxel * np.indices((40, 40, 40)).transpose(1, 2, 3, 0) - [0.0, 0.1, 0.0], axis=-1) - 0.04,
        voxel, tuple(origin), "drop2")
    # A liquid's own viscosity outside settings.viscosity's range is refused in one line.
    before = sim.positions("liquid").shape[0]
    with pytest.raises(ValueError, match="viscosity = -1: expected a number in"):
        sim.add_liquid(drop2, (0, -0.5, 0), viscosity=-1)
    assert sim.positions("liquid").shape[0] == before  # nothing was added
    added = sim.add_liquid(drop2, (0, -0.5, 0), viscosity=0.5)
    # A 4 cm ball at 2 cm spacing: volume / spacing^3 = 33.5 particles, within the sampler's packing.
    assert 20 < added < 60
    n = sim.positions("liquid").shape[0]
    # The second drop carries its own viscosity in the 'viscosity' channel, the scene's drop the
    # settings' (0).
    nu = sim.channel("liquid", "viscosity")
    assert (nu == 0.5).sum() == added and (nu == 0).sum() == n - added
    sim.run()
    # In 1/3 s both drops reach the floor slab (top at y = -0.02; free fall from y = 0.06 takes
    # 0.13 s). Some splash off its edges and fall on; none is inside it: collision projection
    # keeps phi >= 0 of the floor's own level set (1e-3 voxel of projection tolerance).
    x = sim.positions("liquid")
    assert x.shape[0] == n
    assert x[:, 1].min() < 0.0
    assert ((np.abs(x[:, 0]) < 0.15) & (np.abs(x[:, 2]) < 0.15)).sum() > 0
    assert floor.phi(x).min() > -1e-3 * voxel


@pytest.mark.skipif(not EXE, reason="needs the ghostfx program")
def test_study_runs_the_sweep_and_returns_its_table(tmp_path):
    import json
    scene = os.path.join(SOURCE, "examples", "studies", "free_fall", "scene.json")
    spec = {
        "ghostfx_study": 1,
        "scene": scene,
        "sweep": {"settings.substeps": [5, 10]},
        "set": {"settings.frame_range": [1, 3]},
        "metrics": ["free_fall"],
        "output": {"directory": str(tmp_path / "out")},
    }
    path = tmp_path / "study.json"
    path.write_text(json.dumps(spec))
    table = ghostfx.study(path, executable=EXE)
    assert table["settings.substeps"] == [5.0, 10.0]
    # Free fall of a ball: the centre-of-mass error is the integrator's, under 1 % of the drop
    # at either step (the study's own tests bound it the same way).
    assert all(e < 0.01 for e in table["free_fall_com_error"])
    spec["sweep"] = {"settings.substepz": [5]}
    path.write_text(json.dumps(spec))
    with pytest.raises(ValueError, match="substepz"):
        ghostfx.study(path, executable=EXE)


def test_dfsph_pressure_runs_the_dam_break_and_its_checkpoint_names_the_model(tmp_path):
    # The implicit pressure through the same scene keys: CFL steps on the flow speed take fewer
    # steps than the Tait step's 20 a frame, and the column collapses as with Tait (its centre of
    # mass drops by less than free fall, 5.45 mm in 1/30 s).
    scene = ghostfx.load_scene(DAM, {"settings.frame_range": [1, 2], "settings.pressure": "dfsph",
                                     "settings.substeps": 0})
    sim = ghostfx.Simulation(scene)
    start = sim.positions("liquid")
    sim.run(frames=1)
    x = sim.positions("liquid")
    assert np.isfinite(x).all()
    drop = start[:, 1].mean() - x[:, 1].mean()
    assert 0 < drop < 0.5 * 9.81 * (1 / 30) ** 2
    assert sim.steps < 20
    checkpoint = str(tmp_path / "dam.0001.h5")
    sim.save_checkpoint(checkpoint)
    tait = ghostfx.load_scene(DAM, {"settings.frame_range": [1, 2], "settings.substeps": 0})
    with pytest.raises(ValueError, match="pressure"):
        ghostfx.Simulation.resume(tait, checkpoint)


PLUME = os.path.join(SOURCE, "examples", "gas_plume", "scene.json")


def _plume_per_frame(method, turbulence="none"):
    """Visible gas count, centroid height and top (95th percentile of y) after every frame of
    the shipped plume, run with its default settings, the given method and turbulence model."""
    scene = ghostfx.load_scene(PLUME, {"settings.method": method, "outputs.preview": None,
                                       "settings.gas.turbulence": turbulence})
    sim = ghostfx.Simulation(scene)
    rows = []

    def measure(s):
        y = s.positions("gas")[:, 1]
        rows.append((len(y), float(np.mean(y)), float(np.percentile(y, 95))))

    sim.run(on_frame=measure)
    return np.array(rows)


def test_shipped_plume_fast_and_ambient_rise_alike_without_turbulence():
    # [RYY15]'s claim: gas without ambient air looks like gas with it, both without a turbulence
    # model (settings.gas.turbulence "none": the paper's methods). The measure: per frame,
    # the plume's top (95th percentile height of the visible gas) and centroid height, and the
    # visible gas count, compared while both tops are below 90 % of the kill box's height
    # (1.6 m): above it the fast solver's gas leaves the kill box while the baseline's closed
    # box keeps it. Measured 2026-11-28 over 12 sample realisations (settings.gas.seed 1-6,
    # the sampler before and after its growth ran in tiles): top ratio fast / ambient
    # 0.92-1.21, centroid 0.84-1.14 over 27-28 frames, count 0.97-1.23 from frame 9 (the fast
    # source's first fill is a sampled sphere with its surface layer, 187 particles against the
    # 121 air particles the baseline converts, an offset that the emission then dilutes).
    # Tolerances: top 25 %, centroid 20 %, count 25 % (from 0.3 s). The automatic damping
    # without turbulence, C_d = 7 /s, is what makes them agree (C_d = 1 /s: top ratio up to
    # 1.79). With the default entrainment the fast plume's top is 1.07-1.43 times the
    # baseline's (docs/study.md): its entrained air stands for a real plume's, which the
    # baseline's air, as coarse as the gas, does not draw in.
    fast = _plume_per_frame("gas")
    ambient = _plume_per_frame("gas_ambient")
    below = (fast[:, 2] < 0.9 * 1.6) & (ambient[:, 2] < 0.9 * 1.6)
    frames = np.nonzero(below)[0]
    assert len(frames) >= 20, frames
    top = fast[frames, 2] / ambient[frames, 2]
    centroid = fast[frames, 1] / ambient[frames, 1]
    late = frames[frames >= 8]
    count = fast[late, 0] / ambient[late, 0]
    print("[measured] plume fast / ambient over %d frames: top %.2f-%.2f, centroid %.2f-%.2f, "
          "count %.2f-%.2f (from frame 9)" % (len(frames), top.min(), top.max(),
                                             centroid.min(), centroid.max(), count.min(),
                                             count.max()))
    assert np.all(np.abs(top - 1) < 0.25), top
    assert np.all(np.abs(centroid - 1) < 0.20), centroid
    assert np.all(np.abs(count - 1) < 0.25), count
    # The baseline keeps emitting: its visible gas grows through the run (it stopped at 143
    # particles before its sources filled their free room).
    assert ambient[-1, 0] > 5 * ambient[0, 0]


def test_sample_cache_gives_the_same_particles_without_sampling_again(tmp_path):
    # The same scene set up twice through the cache: the second set-up loads the tank and the
    # water (2 shapes) and its particles are the first's, bit for bit.
    ghostfx.set_sample_cache(str(tmp_path / "cache"))
    try:
        scene = ghostfx.load_scene(DAM, {"settings.frame_range": [1, 1]})
        first = ghostfx.Simulation(scene).positions("liquid")
        loaded_before, kept = ghostfx.sample_cache_counts()
        assert kept >= 2
        second = ghostfx.Simulation(scene).positions("liquid")
        loaded, kept_after = ghostfx.sample_cache_counts()
        assert loaded - loaded_before == 2 and kept_after == kept
        assert np.array_equal(first, second)
    finally:
        ghostfx.set_sample_cache("")
    with pytest.raises(OSError, match="sample cache folder"):
        ghostfx.set_sample_cache("/proc/version/cache")
    # "off", as on the command line: no cache, so nothing loaded or kept.
    ghostfx.set_sample_cache("off")
    assert ghostfx.sample_cache_counts() == (0, 0)
    ghostfx.set_sample_cache("")
