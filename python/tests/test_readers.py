"""pytest of the file readers (read_points, read_volume, read_stats, read_checkpoint) on the
files a real run writes: the shipped dam break and gas plume, shortened to one frame.

Each comparison states its tolerance and where it comes from."""
import csv
import os
import subprocess

import numpy as np
import pytest

import ghostfx

SOURCE = os.environ.get("GHOSTFX_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("GHOSTFX_EXE")
DAM = os.path.join(SOURCE, "examples", "dam_break", "scene.json")
PLUME = os.path.join(SOURCE, "examples", "gas_plume", "scene.json")
ONE_FRAME = {"settings.frame_range": [1, 1], "outputs.preview": False}


@pytest.fixture(scope="module")
def dam_frame(tmp_path_factory):
    """One frame of the dam break, simulated and written; (sim, folder)."""
    folder = tmp_path_factory.mktemp("dam")
    sim = ghostfx.Simulation(ghostfx.load_scene(DAM, ONE_FRAME))
    sim.advance_frame()
    sim.write_frame(str(folder))
    return sim, folder


def _by_id(ids):
    order = np.argsort(ids)
    assert len(np.unique(ids)) == len(ids)
    return order


def test_points_read_back_as_the_simulation_holds_them(dam_frame):
    sim, folder = dam_frame
    points = ghostfx.read_points(str(folder / "liquid_points.0001.vdb"))
    # The scene's channels, P first, in their stored types.
    assert list(points) == ["P", "v", "id", "density", "pressure"]
    assert points["P"].dtype == np.float64 and points["P"].shape[1] == 3
    assert points["v"].dtype == np.float32 and points["v"].shape[1] == 3
    assert points["id"].dtype == np.int64
    assert points["density"].dtype == points["pressure"].dtype == np.float32
    n = sim.positions("liquid").shape[0]
    assert all(len(a) == n for a in points.values())

    ids = sim.channel("liquid", "id")
    mine, theirs = _by_id(points["id"]), _by_id(ids)
    assert (points["id"][mine] == ids[theirs]).all()
    # Velocity, density and pressure are stored as float32: exactly the float32 of the
    # solver's value (the solver's Real is float, so in fact exactly its value).
    v = sim.velocities("liquid")[theirs]
    assert (points["v"][mine] == v.astype(np.float32)).all()
    for name in ("density", "pressure"):
        assert (points[name][mine] == sim.channel("liquid", name)[theirs].astype(np.float32)).all()
    # P is stored as a float32 offset in [-0.5, 0.5] voxel from its voxel's centre, so its
    # rounding is at most 2^-25 voxel; the points voxel is at most a few spacings (1.5 cm
    # spacing, 8 points per voxel), so 2^-24 of 0.1 m bounds it with room.
    error = np.abs(points["P"][mine] - sim.positions("liquid")[theirs]).max()
    assert error <= 0.1 * 2.0 ** -24, error


def test_the_surface_and_density_read_back_dense_and_active(dam_frame):
    sim, folder = dam_frame
    file = str(folder / "liquid.0001.vdb")
    surface = ghostfx.read_volume(file, "surface")
    assert surface.grid_class == "level set" and surface.values.dtype == np.float32
    assert surface.values.ndim == 3 and not surface.active
    # The level set holds its narrow band; the background is its half-width (3 voxels).
    assert surface.background == pytest.approx(3 * surface.voxel_size, rel=1e-6)
    # The transform puts values[0, 0, 0] at origin, one voxel per index step.
    assert np.allclose(surface.index_to_world(np.array(surface.index_min)), surface.origin)
    assert np.allclose(np.diag(surface.transform)[:3], surface.voxel_size)

    # The same grid through LevelSet.phi (trilinear) at the voxel centres of a slab: at a voxel
    # centre trilinear interpolation is the voxel's value. phi takes the point in float32 (the
    # build's Real): a world coordinate below 1 m is off by at most 2^-24 m, which moves phi
    # (|grad phi| = 1, a distance) by as much; the bound is twice that (measured: 1.3e-8 m).
    shape = ghostfx.LevelSet.from_vdb(file, "surface")
    i = np.arange(surface.values.shape[0])
    j = np.full_like(i, surface.values.shape[1] // 2)
    k = np.full_like(i, surface.values.shape[2] // 2)
    ijk = np.stack([i, j, k], axis=1) + np.array(surface.index_min)
    phi = shape.phi(surface.index_to_world(ijk))
    assert np.abs(surface.index_to_world(ijk)).max() < 1.0
    assert np.abs(phi - surface.values[i, j, k]).max() <= 2.0 ** -23
    # The liquid's particles are inside the surface (phi < 0 at most of them: the surface
    # is built around the particles at a fraction of a spacing).
    inside = shape.phi(sim.positions("liquid")) < 0
    assert inside.mean() > 0.95

    # Active voxels: as many as info's count; each value is the dense array's at its index.
    active = ghostfx.read_volume(file, "surface", active=True)
    assert active.ijk.dtype == np.int32 and active.world.shape == active.ijk.shape
    rel = active.ijk - np.array(surface.index_min)
    assert (surface.values[rel[:, 0], rel[:, 1], rel[:, 2]] == active.values).all()
    assert np.allclose(active.world, active.index_to_world(active.ijk), rtol=0, atol=1e-12)
    assert (np.abs(active.values) < surface.background).all()

    density = ghostfx.read_volume(file, "density")
    assert density.grid_class == "fog volume" and density.background == 0
    # rho / rho0, and mass (kg) = rest_density * sum(values) * voxel^3 (the grid's "units"
    # metadata): the liquid's mass, to the splat's sampling of the kernel on the voxel
    # lattice (measured 6.4e-5 relative; the bound allows 1e-3).
    assert "rho/rho0" in density.metadata["units"]
    mass = density.metadata["rest_density"] * density.values.sum(dtype=np.float64) * density.voxel_size ** 3
    assert mass == pytest.approx(sim.channel("liquid", "mass").sum(), rel=1e-3)
    # At about rest density: the peak within 20 % of 1 (a slightly compressed column).
    assert 0.8 < density.values.max() < 1.2
    vel = ghostfx.read_volume(file, "vel")
    assert vel.values.shape[3] == 3 and vel.values.dtype == np.float32
    # The velocity grid's speeds stay below the fastest particle's (it averages them).
    speed = np.linalg.norm(vel.values, axis=3).max()
    assert speed <= np.linalg.norm(sim.velocities("liquid"), axis=1).max() * (1 + 1e-6)


def test_read_errors_name_the_file_and_the_grid(dam_frame):
    _, folder = dam_frame
    file = str(folder / "liquid.0001.vdb")
    missing = str(folder / "nothing.vdb")
    with pytest.raises(OSError) as error:
        ghostfx.read_points(missing)
    assert str(error.value) == f"read_points: file '{missing}' does not exist"
    with pytest.raises(ValueError) as error:
        ghostfx.read_points(file)
    assert str(error.value).startswith(f"read_points: file '{file}' has no point grid (grids: ")
    with pytest.raises(ValueError) as error:
        ghostfx.read_volume(file, "temperature")
    assert str(error.value).startswith(f"read_volume: file '{file}' has no grid 'temperature'")
    points = str(folder / "liquid_points.0001.vdb")
    with pytest.raises(ValueError, match="is a point grid, expected a volume"):
        ghostfx.read_volume(points, "particles")
    with pytest.raises(ValueError, match="index coordinates of shape"):
        ghostfx.read_volume(file, "surface").index_to_world(np.zeros((2, 2)))


def test_info_prints_the_ranges_read_points_gives(dam_frame):
    if not EXE:
        pytest.skip("GHOSTFX_EXE is not set (ctest sets it)")
    _, folder = dam_frame
    file = str(folder / "liquid_points.0001.vdb")
    points = ghostfx.read_points(file)
    info = subprocess.run([EXE, "info", file], capture_output=True, text=True, check=True).stdout
    lines = info.splitlines()
    ranges = lines[next(n for n, l in enumerate(lines) if l.startswith("  attribute ranges")):]
    line = next(l for l in ranges if l.strip().startswith("id "))
    ids = points["id"]
    assert line.split()[1:] == [str(ids.min()), "..", f"{ids.max()},", "mean", f"{ids.mean():g}"]
    density = next(l for l in ranges if l.strip().startswith("density "))
    low = float(density.split()[1])
    assert low == pytest.approx(float(points["density"].min()), rel=1e-5)  # printed to 6 digits


def test_stats_and_checkpoint_of_a_run_read_back(tmp_path):
    if not EXE:
        pytest.skip("GHOSTFX_EXE is not set (ctest sets it)")
    subprocess.run([EXE, "run", DAM, "-q", "--out", str(tmp_path), "-D", "settings.frame_range=[1,1]",
                    "-D", "outputs.preview=false"], check=True)
    stats = ghostfx.read_stats(str(tmp_path / "stats.h5"))
    with open(tmp_path / "stats.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    # The CSV beside it holds the same rows, each number in a form that reads back exactly.
    assert list(stats) == list(rows[0])
    for name, values in stats.items():
        assert values.dtype == np.float64
        assert (values == np.array([float(r[name]) for r in rows])).all(), name
    # The columns Simulation.statistics() gives, and the same simulation: every column but the
    # wall-clock timings (t_*) is equal step for step (the solver is deterministic).
    sim = ghostfx.Simulation(ghostfx.load_scene(DAM, ONE_FRAME))
    sim.advance_frame()
    mine = sim.statistics()
    assert list(mine) == list(stats)
    for name in stats:
        if not name.startswith("t_") and not name.startswith("bytes"):
            assert (mine[name] == stats[name]).all(), name
    assert stats["time"][-1] == pytest.approx(1 / 30)

    states = ghostfx.read_checkpoint(str(tmp_path / "checkpoint.0001.h5"))
    assert [s["solver"] for s in states] == ["ghost"]
    particles = states[0]["particles"]
    liquid = particles["kind"] == 0  # ParticleKind::Liquid
    ids = sim.channel("liquid", "id")
    assert liquid.sum() == len(ids)
    mine, theirs = _by_id(particles["id"][liquid]), _by_id(ids)
    # Stored in the build's precision: exactly the simulation's values.
    assert (particles["position"][liquid][mine] == sim.positions("liquid")[theirs]).all()
    assert (particles["velocity"][liquid][mine] == sim.velocities("liquid")[theirs]).all()
    assert states[0]["integers"]["step"] == sim.steps
    assert states[0]["reals"]["time"] == pytest.approx(sim.time, rel=1e-12)


def test_gas_points_read_back_with_their_temperature(tmp_path):
    sim = ghostfx.Simulation(ghostfx.load_scene(PLUME, ONE_FRAME))
    sim.advance_frame()
    sim.write_frame(str(tmp_path))
    points = ghostfx.read_points(str(tmp_path / "gas_points.0001.vdb"))
    assert list(points) == ["P", "v", "id", "temperature", "density"]
    ids = sim.channel("gas", "id")
    assert len(ids) > 0 and len(points["id"]) == len(ids)
    mine, theirs = _by_id(points["id"]), _by_id(ids)
    # K, stored as float32: exactly the solver's float value.
    temperature = sim.channel("gas", "temperature")[theirs].astype(np.float32)
    assert (points["temperature"][mine] == temperature).all()
    # As for the liquid: 2^-24 of a points voxel of at most 0.2 m (3 cm spacing).
    error = np.abs(points["P"][mine] - sim.positions("gas")[theirs]).max()
    assert error <= 0.2 * 2.0 ** -24, error
    gas = ghostfx.read_volume(str(tmp_path / "gas.0001.vdb"), "temperature", active=True)
    assert gas.values.dtype == np.float32 and len(gas.values) == len(gas.ijk) > 0


def test_a_mesh_reads_back_as_the_level_set_meshes(dam_frame, tmp_path):
    """mesh_volume of the written surface equals the .ply outputs.mesh writes from the same
    frame bit for bit (the same volumeToMesh of the same grid), and the closed mesh encloses
    the level set's liquid volume within 1 % (the pipeline's bound for a mesh; MeshFile's tests measure
    under 0.5 %). The level set's volume is the sum of a smeared Heaviside of -phi over the
    voxels (half-width one voxel), second-order in the voxel size where phi is a distance;
    counting the voxel centres with phi < 0 is only first-order (1.6 % low here)."""
    _, folder = dam_frame
    volume = str(folder / "liquid.0001.vdb")
    mesh = ghostfx.mesh_volume(volume)
    surface = ghostfx.read_volume(volume, "surface")
    x, eps = -surface.values.astype(np.float64), surface.voxel_size
    heaviside = np.clip(0.5 + x / (2 * eps) + np.sin(np.pi * np.clip(x / eps, -1, 1)) / (2 * np.pi),
                        0, 1)
    inside = heaviside.sum() * surface.voxel_size ** 3
    p, t = mesh["points"].astype(np.float64), mesh["triangles"]
    enclosed = np.einsum("ij,ij->i", p[t[:, 0]], np.cross(p[t[:, 1]], p[t[:, 2]])).sum() / 6
    assert enclosed == pytest.approx(inside, rel=0.01)
    assert mesh["velocities"].shape == mesh["points"].shape
    if not EXE:
        pytest.skip("GHOSTFX_EXE is not set")
    out = tmp_path / "run"
    subprocess.run([EXE, "run", DAM, "--quiet", "--out", str(out), "--frames", "1-1",
                    "-D", "outputs.preview=false", "-D", 'outputs.mesh.file="liquid.$F4.ply"'],
                   check=True)
    written = ghostfx.read_mesh(str(out / "liquid.0001.ply"))
    remeshed = ghostfx.mesh_volume(str(out / "liquid.0001.vdb"))
    for key in ("points", "normals", "triangles", "velocities"):
        assert np.array_equal(written[key], remeshed[key]), key
    with pytest.raises(ValueError, match="has no grid 'foam'"):
        ghostfx.mesh_volume(volume, "foam")
    with pytest.raises(ValueError, match="is not a float level set"):
        ghostfx.mesh_volume(volume, "density")
