"""pytest suite of rigid bodies a script adds (Simulation.add_body) and reads and pushes
(body, apply_force, apply_torque), in real Ghost SPH runs: a 30 x 30 cm open tank at 2 cm
spacing with 15 cm of water. Each test states where its bound comes from."""
import numpy as np
import pytest

import ghostfx

FPS = 50.0
G = 9.81


def box(lo, hi, name, voxel=0.005):
    """A box level set from a dense signed-distance array (exact inside and out)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    origin = lo - 4 * voxel
    n = np.ceil((hi - lo) / voxel).astype(int) + 9
    q = np.abs(origin + voxel * np.indices(tuple(n)).transpose(1, 2, 3, 0) - (lo + hi) / 2) - (hi - lo) / 2
    sdf = np.linalg.norm(np.maximum(q, 0), axis=-1) + np.minimum(q.max(axis=-1), 0)
    return ghostfx.LevelSet.from_array(sdf, voxel, tuple(origin), name)


def tank_document(frames=10, height=0.6):
    """An open tank 30 x `height` x 30 cm (y up), 15 cm of water, 2 cm spacing, CFL steps."""
    return {"ghostfx_scene": 1,
           "settings": {"method": "ghost", "spacing": 0.02, "frame_rate": FPS, "substeps": 0,
                        "frame_range": [1, frames], "seed": 3},
           "solids": [{"name": "tank",
                       "geometry": {"container": {"min": [0, 0, 0], "max": [0.3, height, 0.3]}}}],
           "liquids": [{"name": "water",
                        "geometry": {"box": {"min": [0, 0, 0], "max": [0.3, 0.15, 0.3]}}}]}


def tank_scene(tmp_path, frames=10, height=0.6):
    return ghostfx.load_scene(tank_document(frames, height), folder=tmp_path)


# The 10 x 6 x 10 cm box: 4 cm above the water (it falls onto it), or high in the air.
FLOATING = ([0.10, 0.19, 0.10], [0.20, 0.25, 0.20])
IN_AIR = ([0.10, 0.44, 0.10], [0.20, 0.50, 0.20])
VOLUME = 0.10 * 0.06 * 0.10


def test_a_body_reads_its_mass_properties_and_state(tmp_path):
    sim = ghostfx.Simulation(tank_scene(tmp_path))
    sim.add_body(box(*FLOATING, "crate"), density=500)
    b = sim.body("crate")
    # The level set's volume integral of the box (5 mm voxels) is 0.4 % under the exact
    # 10 x 6 x 10 cm; the issue asks for 1 %.
    assert b["volume"] == pytest.approx(VOLUME, rel=0.01)
    assert b["mass"] == pytest.approx(500 * VOLUME, rel=0.01)
    assert b["mass"] == pytest.approx(500 * b["volume"], rel=1e-12)
    np.testing.assert_allclose(b["position"], [0.15, 0.22, 0.15], atol=1e-4)
    # A solid box's inertia about its centre: m (b^2 + c^2) / 12 on the diagonal.
    m = b["mass"]
    expected = np.diag([m * (0.06**2 + 0.1**2), m * (0.1**2 + 0.1**2), m * (0.1**2 + 0.06**2)]) / 12
    np.testing.assert_allclose(b["inertia"], expected, rtol=0.02, atol=1e-9 * m)
    upward = []
    for _ in range(8):
        sim.advance_frame()
        upward.append(sim.body("crate")["liquid_force"][1])
    b = sim.body("crate")
    for key in ("position", "orientation", "rotation", "velocity", "angular_velocity",
                "inertia", "liquid_force", "liquid_torque"):
        assert np.all(np.isfinite(b[key])), key
    q = np.asarray(b["orientation"])
    assert np.linalg.norm(q) == pytest.approx(1, abs=1e-12)  # normalised by the body
    # The rotation matrix is the quaternion's; the inertia is R I_body R^T, so its
    # eigenvalues stay the box's.
    w, x, y, z = q
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    np.testing.assert_allclose(b["rotation"], r, atol=1e-12)
    np.testing.assert_allclose(np.linalg.eigvalsh(b["inertia"]), np.sort(np.diag(expected)),
                               rtol=0.02)
    # Once the box has fallen onto the water (within 4 frames: 4 cm at g), the water holds it
    # up: the liquid's force on it points up, on average over the frames after.
    assert np.mean(upward[3:]) > 0


def test_a_body_in_air_falls_freely(tmp_path):
    sim = ghostfx.Simulation(tank_scene(tmp_path))
    sim.add_body(box(*IN_AIR, "crate"), density=500)
    y0 = sim.body("crate")["position"][1]
    steps = []
    sim.on_step(lambda s, dt: steps.append(dt))
    sim.advance_frame()
    b = sim.body("crate")
    t = 1 / FPS
    # 25 cm above the water no liquid reaches it: gravity alone, v = g t (the 1 %),
    # and no liquid force at all.
    assert sim.time == pytest.approx(t, rel=1e-12)
    assert b["velocity"][1] == pytest.approx(-G * t, rel=0.01)
    assert abs(b["velocity"][0]) < 1e-12 and abs(b["velocity"][2]) < 1e-12
    assert np.all(np.asarray(b["liquid_force"]) == 0)
    # The body steps by semi-implicit Euler (velocity first, then position): over the frame's
    # steps dt_k it falls sum_k g (dt_1 + ... + dt_k) dt_k, g t^2 / 2 plus g dt t / 2 for equal
    # steps; to the rounding of the float32 steps the observer sees (1e-6).
    v, fall = 0.0, 0.0
    for dt in steps:
        v += G * dt
        fall += v * dt
    assert sum(steps) == pytest.approx(t, rel=1e-6)  # the steps dt are float32 (sph::Real)
    assert y0 - b["position"][1] == pytest.approx(fall, rel=1e-6)
    assert fall > G * t * t / 2


def test_apply_force_of_its_weight_holds_a_body_for_one_frame(tmp_path):
    sim = ghostfx.Simulation(tank_scene(tmp_path))
    sim.add_body(box(*IN_AIR, "crate"), mass=0.3)
    m = sim.body("crate")["mass"]
    assert m == 0.3
    sim.apply_force("crate", (0, m * G, 0))
    sim.advance_frame()
    # m g upward cancels gravity (1e-3 m/s over a frame: the bound; in air nothing else
    # acts, so it is exact to rounding).
    assert np.abs(sim.body("crate")["velocity"]).max() < 1e-3
    # The force lasted that frame only: the next frame the body falls at g.
    sim.advance_frame()
    assert sim.body("crate")["velocity"][1] == pytest.approx(-G / FPS, rel=0.01)


def test_apply_torque_spins_a_body_at_its_inertia(tmp_path):
    sim = ghostfx.Simulation(tank_scene(tmp_path))
    sim.add_body(box(*IN_AIR, "crate"), density=500)
    i_yy = sim.body("crate")["inertia"][1][1]
    tau = 1e-3
    sim.apply_torque("crate", (0, tau, 0))
    sim.advance_frame()
    # About a principal axis, omega = tau t / I_yy (the angular momentum is exact: L = tau t).
    omega = sim.body("crate")["angular_velocity"]
    assert omega[1] == pytest.approx(tau / FPS / i_yy, rel=1e-6)


def test_body_errors_name_the_body(tmp_path):
    sim = ghostfx.Simulation(tank_scene(tmp_path))
    sim.add_body(box(*IN_AIR, "crate"), density=500)
    with pytest.raises(ValueError) as e:
        sim.body("tank")
    assert str(e.value) == "body 'tank': the simulation has no body of that name (bodies: 'crate')"
    with pytest.raises(ValueError) as e:
        sim.apply_force("lid", (0, 1, 0))
    assert str(e.value) == "body 'lid': the simulation has no body of that name (bodies: 'crate')"
    with pytest.raises(ValueError) as e:
        sim.add_body(box(*FLOATING, "crate"), density=500)
    assert str(e.value) == ("body 'crate': the simulation has one of that name already "
                            "('tank', 'crate'); give another name=...")
    with pytest.raises(ValueError) as e:
        sim.add_body(box(*FLOATING, "lid"), density=500, mass=1)
    assert str(e.value) == "body 'lid': give density=... (kg/m^3) or mass=... (kg), not both"
    with pytest.raises(ValueError) as e:
        sim.add_body(box(*FLOATING, "lid"))
    assert str(e.value) == "body 'lid': give density=... (kg/m^3) or mass=... (kg), one of them"
    with pytest.raises(ValueError) as e:
        sim.add_body(box(*FLOATING, "lid"), density=500, restitution=2)
    assert str(e.value) == "dynamic solid 'lid': restitution 2: expected 0 to 1"
    with pytest.raises(ValueError) as e:
        sim.apply_force("crate", (0, float("nan"), 0))
    assert str(e.value) == "body 'crate': the force or torque is not finite"
    with pytest.raises(ValueError) as e:
        sim.set_solid_velocity("crate", (1, 0, 0))
    assert str(e.value) == ("solid 'crate' is a body: the liquid, gravity and its contacts move "
                            "it; push it with apply_force")
    sim.advance_frame()
    with pytest.raises(ValueError) as e:
        sim.add_body(box(*FLOATING, "lid"), density=500)
    assert str(e.value) == ("body 'lid': bodies are added before the first step (this "
                            "simulation has taken %d)" % sim.steps)


def test_resume_continues_an_added_body_bit_for_bit(tmp_path):
    def started():
        sim = ghostfx.Simulation(tank_scene(tmp_path))
        sim.add_solid(box([0.02, 0.0, 0.02], [0.06, 0.25, 0.06], "post"))
        sim.add_body(box(*FLOATING, "crate"), density=500, angular_velocity=(0, 0.5, 0),
                     restitution=0.1, friction=0.3)
        sim.add_solid(box([0.24, 0.0, 0.24], [0.28, 0.25, 0.28], "post2"))
        sim.advance_frame()
        return sim
    straight = started()
    checkpoint = str(tmp_path / "c.h5")
    straight.save_checkpoint(checkpoint)
    for _ in range(4):
        straight.advance_frame()
    resumed = ghostfx.Simulation.resume(tank_scene(tmp_path), checkpoint)
    for _ in range(4):
        resumed.advance_frame()
    for kind in ("liquid", "air", "solid"):
        assert np.array_equal(resumed.positions(kind), straight.positions(kind)), kind
        assert np.array_equal(resumed.velocities(kind), straight.velocities(kind)), kind
    a, b = resumed.body("crate"), straight.body("crate")
    # Bit for bit: the checkpoint keeps the body's mass properties with its state, so the shape
    # its attachment stream gives back (which can differ in its last bits) does not enter.
    for key in ("position", "velocity", "mass", "volume", "liquid_force", "liquid_torque",
                "orientation", "rotation", "angular_velocity", "inertia"):
        assert np.array_equal(a[key], b[key]), key
    # The solids keep their names and order: the second post is still a static solid.
    with pytest.raises(ValueError):
        resumed.body("post2")


def test_bodies_need_a_ghost_sph_liquid(tmp_path):
    gas = ghostfx.load_scene({
        "ghostfx_scene": 1,
        "settings": {"method": "gas", "spacing": 0.03, "frame_range": [1, 2], "gas": {"seed": 1}},
        "domain": {"kill_box": {"min": [-0.4, -0.05, -0.4], "max": [0.4, 1.0, 0.4]}},
        "gas_sources": [{"name": "later", "start": 100,
                         "geometry": {"sphere": {"center": [0.3, 0.1, 0.3], "radius": 0.05}}}],
    }, folder=tmp_path)
    sim = ghostfx.Simulation(gas)
    with pytest.raises(ValueError) as e:
        sim.add_body(box(*IN_AIR, "crate"), density=500)
    assert str(e.value) == ("solid 'crate': adding solids from a script is supported in liquid "
                            "scenes only")
    with pytest.raises(ValueError) as e:
        sim.body("crate")
    assert str(e.value) == "body 'crate': the simulation has no body of that name (bodies: none)"
    basic = ghostfx.Simulation(ghostfx.load_scene(
        {**tank_document(), "settings": {**tank_document()["settings"], "method": "basic"}},
        folder=tmp_path))
    with pytest.raises(ValueError) as e:
        basic.add_body(box(*IN_AIR, "crate"), density=500)
    assert str(e.value) == "dynamic solid 'crate': dynamic solids need method 'ghost', not 'basic'"
