/// @file   module.cc
/// @brief  The `ghostfx` Python module (pybind11): scenes, simulations, particles as NumPy arrays
///         and Poisson-disk sampling, over the same code the command line runs (vdbio::readScene,
///         cmd::makeSimulation, sph::PoissonDiskSampler).
/// @details Particle arrays are copies: the solvers reorder and grow their particle storage every
///          step, so a view would dangle after the next advance_frame(). Long calls (a frame, a
///          sampling) release the GIL. Errors of the library keep their one-line text: a bad scene
///          raises ValueError with the message the command line prints after "ghostfx: error: ".
#include "FrameWriter.h"
#include "LiquidScene.h"
#include "Readers.h"
#include "ScriptInputs.h"
#include "Simulation.h"
#include "StopSignals.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/PoissonSampler.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/Scene.h>
#include <ghostfx/vdbio/Stats.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace py = pybind11;
using namespace ghostfx;

namespace {

/// `-D` assignments from a dict of dotted keys: {"settings.stiffness": 5000} ->
/// "settings.stiffness=5000" (values as JSON, as the command line parses them).
std::vector<std::string> assignments(const py::object& overrides)
{
    std::vector<std::string> out;
    if (overrides.is_none()) return out;
    const py::module_ json = py::module_::import("json");
    for (const auto& item : overrides.cast<py::dict>()) {
        const std::string key = py::str(item.first);
        out.push_back(key + "=" + json.attr("dumps")(item.second).cast<std::string>());
    }
    return out;
}

/// A read scene, kept with what it was read from.
struct PyScene
{
    std::shared_ptr<const vdbio::Scene> scene;
};

/// The scene document's `settings` object (after the overrides) as a Python dict.
py::object settingsOf(const vdbio::Scene& scene)
{
    const vdbio::Json& doc = *scene.document;
    const auto s = doc.find("settings");
    const std::string text = s == doc.end() ? "{}" : s->dump();
    return py::module_::import("json").attr("loads")(text);
}

sph::ParticleKind kindFromName(const std::string& name)
{
    if (name == "liquid") return sph::ParticleKind::Liquid;
    if (name == "air") return sph::ParticleKind::GhostAir;
    if (name == "solid") return sph::ParticleKind::GhostSolid;
    if (name == "gas") return sph::ParticleKind::Gas;
    if (name == "boundary") return sph::ParticleKind::Boundary;
    throw ValueError("particle kind '" + name
                     + "': expected 'liquid', 'air', 'solid', 'gas' or 'boundary'");
}

/// One medium's particles of `kind`, ghosts included (a copy; see the file comment). With
/// `pendingMass`, before the medium's first step the particles whose mass is still 0 get the
/// mass that step will give them (the solver's mass scaling, measured apart: costs a sampling).
sph::ParticleSet particlesOf(const cmd::Simulation& sim, sph::ParticleKind kind,
                             bool pendingMass = false)
{
    for (const cmd::OutputMedium& m : sim.media()) {
        const bool listed =
            std::find(m.kinds.begin(), m.kinds.end(), kind) != m.kinds.end()
            || std::find(m.ghostKinds.begin(), m.ghostKinds.end(), kind) != m.ghostKinds.end();
        if (!listed) continue;
        sph::ParticleSet all = m.withGhosts ? m.withGhosts() : *m.particles;
        std::vector<std::uint8_t> keep(all.size());
        for (std::size_t i = 0; i < all.size(); ++i) keep[i] = all.kinds()[i] == kind;
        sph::ParticleSet out = all.select(keep);
        std::vector<sph::Real>& mass = out.masses();
        const bool unset = std::find(mass.begin(), mass.end(), sph::Real(0)) != mass.end();
        const double pending = pendingMass && unset && m.pendingMass ? m.pendingMass() : 0.0;
        if (pending > 0) std::replace(mass.begin(), mass.end(), sph::Real(0), sph::Real(pending));
        return out;
    }
    return sph::ParticleSet();
}

py::array_t<double> vectors(const std::vector<sph::Vec3>& v)
{
    py::array_t<double> a({py::ssize_t(v.size()), py::ssize_t(3)});
    auto w = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < v.size(); ++i) {
        for (int c = 0; c < 3; ++c) w(py::ssize_t(i), c) = double(v[i][c]);
    }
    return a;
}

/// A level set from a dense signed-distance array sdf[i, j, k] at world points
/// origin + voxel (i, j, k) (negative inside): the narrow band of 3 voxels is kept, the
/// inside is filled, and the grid is checked as every other level set is.
sph::LevelSet levelSetFromArray(
    const py::array_t<float, py::array::c_style | py::array::forcecast>& sdf, double voxel,
    const std::array<double, 3>& origin, const std::string& name)
{
    if (sdf.ndim() != 3) {
        throw ValueError("level set '" + name + "': expected a 3-D array of signed distances, got "
                         + std::to_string(sdf.ndim()) + " dimensions");
    }
    if (!(voxel > 0) || !std::isfinite(voxel)) {
        throw ValueError("level set '" + name + "': voxel_size = " + std::to_string(voxel)
                         + ": expected a number > 0");
    }
    const float background = float(3 * voxel);
    auto grid = openvdb::FloatGrid::create(background);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    grid->transform().postTranslate(openvdb::Vec3d(origin[0], origin[1], origin[2]));
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    grid->setName(name);
    auto a = sdf.unchecked<3>();
    auto acc = grid->getAccessor();
    for (py::ssize_t i = 0; i < a.shape(0); ++i) {
        for (py::ssize_t j = 0; j < a.shape(1); ++j) {
            for (py::ssize_t k = 0; k < a.shape(2); ++k) {
                const float v = a(i, j, k);
                if (!std::isfinite(v)) {
                    throw ValueError("level set '" + name + "': sdf[" + std::to_string(i) + ", "
                                     + std::to_string(j) + ", " + std::to_string(k)
                                     + "] is not finite");
                }
                if (std::abs(v) < background)
                    acc.setValue(openvdb::Coord(int(i), int(j), int(k)), v);
            }
        }
    }
    openvdb::tools::signedFloodFill(grid->tree());
    return sph::makeLevelSet(grid, name);
}

/// The level set's values over the index box of its active voxels: (array, origin).
std::pair<py::array_t<float>, std::array<double, 3>> levelSetToArray(const sph::LevelSet& shape)
{
    const openvdb::FloatGrid::ConstPtr grid = sph::gridOf(shape);
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    const openvdb::Coord dim = box.dim();
    py::array_t<float> out({py::ssize_t(dim.x()), py::ssize_t(dim.y()), py::ssize_t(dim.z())});
    auto w = out.mutable_unchecked<3>();
    auto acc = grid->getConstAccessor();
    for (int i = 0; i < dim.x(); ++i) {
        for (int j = 0; j < dim.y(); ++j) {
            for (int k = 0; k < dim.z(); ++k)
                w(i, j, k) = acc.getValue(box.min() + openvdb::Coord(i, j, k));
        }
    }
    const openvdb::Vec3d o = grid->indexToWorld(box.min());
    return {out, {o.x(), o.y(), o.z()}};
}

/// Poisson-disk samples of `shape` at `spacing` (m), sampled without the GIL.
py::array_t<double> poissonSamples(const sph::LevelSet& shape, double spacing, std::uint64_t seed)
{
    sph::SampleSet samples;
    {
        py::gil_scoped_release release;
        sph::PoissonSettings settings = sph::PoissonSettings::forSpacing(sph::Real(spacing));
        settings.seed = seed;
        samples = sph::PoissonDiskSampler(settings).sampleVolume(shape);
    }
    return vectors(samples.positions);
}

/// The Python list of motion keys [{"time", "translate", "rotate"}, ...] (or the scene's
/// {"keys": [...]} object) as a keyed motion, read by the scene reader's own rules.
sph::KeyedMotion motionFromPython(const py::object& motion, const std::string& what)
{
    const py::module_ json = py::module_::import("json");
    py::object object = motion;
    if (!py::isinstance<py::dict>(motion)) {
        py::dict keys;
        keys["keys"] = motion;
        object = keys;
    }
    auto doc = std::make_shared<const vdbio::Json>(
        vdbio::Json::parse(json.attr("dumps")(object).cast<std::string>()));
    return vdbio::readMotion(vdbio::JsonObject(doc, doc.get(), "motion", what, "script"));
}

using FloatArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

sph::Vec3d vec3(const std::array<double, 3>& v) { return sph::Vec3d(v[0], v[1], v[2]); }
std::array<double, 3> array3(const sph::Vec3d& v) { return {v[0], v[1], v[2]}; }

py::array_t<double> matrix3(const openvdb::math::Mat3d& m)
{
    py::array_t<double> out({3, 3});
    auto w = out.mutable_unchecked<2>();
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) w(i, j) = m(i, j);
    }
    return out;
}

/// What the step observer calls besides the statistics: on_step(sim, dt) callbacks, those of
/// sim.on_step() and the one of the run() in progress; `self` is the Python object of the
/// simulation stepping (set for the length of each advance).
struct StepHooks
{
    std::vector<py::object> callbacks;
    py::object runCallback;
    PyObject* self = nullptr;

    void call(double dt) const
    {
        if (callbacks.empty() && !runCallback) return;
        py::gil_scoped_acquire gil;
        const py::handle sim(self);
        for (const py::object& cb : callbacks) cb(sim, dt);
        if (runCallback) runCallback(sim, dt);
    }
};

/// One name among entries that each have one (solids, emitters, gas sources): "'a', 'b'".
template <typename Entries>
std::string namesOf(const Entries& entries)
{
    std::string known;
    for (const auto& e : entries) known += (known.empty() ? "'" : ", '") + e.name + "'";
    return known.empty() ? "none" : known;
}

template <typename Entries>
void refuseDuplicate(const Entries& entries, const std::string& name, const char* what)
{
    for (const auto& e : entries) {
        if (e.name == name) {
            throw ValueError(msg(what, " '", name,
                                 "': the simulation has one of that name already (",
                                 namesOf(entries), "); give another name=..."));
        }
    }
}

class PySimulation
{
public:
    explicit PySimulation(const PyScene& scene) : PySimulation(scene.scene, {}, nullptr) {}

    /// A simulation continuing from a checkpoint written for the same scene settings (the
    /// checkpoint is refused otherwise, naming the first differing key), with the solids,
    /// emitters, gas sources and solid velocities the script had added or set.
    static PySimulation resume(const PyScene& scene, const std::string& path)
    {
        const std::vector<sph::SolverState> states =
            vdbio::readCheckpointStates(path, cmd::checkpointFingerprint(*scene.scene));
        python::ScriptInputs inputs =
            python::fromAttachments(vdbio::readCheckpointAttachments(path), path);
        return PySimulation(scene.scene, std::move(inputs), &states);
    }

    /// The scene's outputs of the current frame (points, volume, preview), into `folder` or
    /// the scene's outputs.directory; the same files `ghostfx run` writes.
    void writeFrame(py::object folder) const
    {
        const std::string dir =
            folder.is_none() ? mScene->outputs.directory : py::str(folder).cast<std::string>();
        py::gil_scoped_release release;
        vdbio::ensureWritableDirectory(dir);
        cmd::writeFrameOutputs(*mScene, cmd::snapshotFrame(mScene->outputs, *mSim, mSim->frame()),
                               dir);
    }

    /// The index of the solid `name` (the scene's, then the script's), or a ValueError naming
    /// the solids there are.
    std::size_t solidIndex(const std::string& name) const
    {
        const auto& solids = mScene->solids;
        for (std::size_t i = 0; i < solids.size(); ++i) {
            if (solids[i].name == name) return i;
        }
        throw ValueError("solid '" + name
                         + "': the scene has no such solid (solids: " + namesOf(solids) + ")");
    }

    /// (rotation 3x3, translation (m)): where the solid `name` is now, its level set's local
    /// frame placed in the world as x_world = rotation x + translation.
    py::tuple solidPlacement(const std::string& name) const
    {
        const std::size_t index = solidIndex(name);
        const std::vector<sph::RigidTransform> placed = mSim->solidPlacements();
        if (index >= placed.size()) {
            throw ValueError("solid '" + name + "': this simulation does not place solids");
        }
        py::array_t<double> rotation({3, 3});
        auto r = rotation.mutable_unchecked<2>();
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) r(i, j) = double(placed[index].rotation(i, j));
        }
        const sph::Vec3d t(placed[index].translation);
        return py::make_tuple(rotation, std::array<double, 3>{t.x(), t.y(), t.z()});
    }

    /// From now on, solid `name` moves at `velocity` (m/s) from where it is, without turning.
    void setSolidVelocity(const std::string& name, const std::array<double, 3>& velocity)
    {
        const std::size_t index = solidIndex(name);
        if (mSim->body(index)) {
            throw ValueError("solid '" + name
                             + "' is a body: the liquid, gravity and its contacts move it; push "
                               "it with apply_force");
        }
        python::SolidVelocity v;
        v.time = mSim->time();
        v.start = motionOf(index)(v.time);
        v.velocity = vec3(velocity);
        mSim->setSolidMotion(index, v.motion());
        mInputs.velocities[index] = v;
    }

    void addSolid(const sph::LevelSet& shape, const std::array<double, 3>& velocity,
                  const py::object& name, const py::object& motion)
    {
        vdbio::SceneSolid solid(name.is_none() ? shape.name() : name.cast<std::string>(),
                                "add_solid", shape);
        refuseDuplicate(mScene->solids, solid.name, "solid");
        solid.velocity = vec3(velocity);
        if (!motion.is_none()) {
            if (solid.velocity != sph::Vec3d(0.0)) {
                throw ValueError("solid '" + solid.name
                                 + "': give either a velocity or motion keys, not both");
            }
            solid.motion = motionFromPython(motion, "add_solid('" + solid.name + "')");
        }
        {
            py::gil_scoped_release release;
            mSim->addSolid(solid);
        }
        mScene->solids.push_back(solid);
        mInputs.solids.push_back(solid);
    }

    void addEmitter(const sph::LevelSet& shape, const std::array<double, 3>& velocity, double start,
                    double end, const py::object& name, const py::object& motion,
                    std::optional<double> viscosity)
    {
        vdbio::SceneEmitter e(name.is_none() ? shape.name() : name.cast<std::string>(),
                              "add_emitter", shape);
        refuseDuplicate(mScene->emitters, e.name, "emitter");
        e.velocity = vec3(velocity);
        e.start = start;
        e.end = end;
        e.viscosity = viscosity;
        if (!motion.is_none()) e.motion = motionFromPython(motion, "add_emitter('" + e.name + "')");
        mSim->addEmitter(e);
        mScene->emitters.push_back(e);
        mInputs.emitters.push_back(e);
    }

    void addGasSource(const sph::LevelSet& shape, const std::array<double, 3>& velocity,
                      double temperature, double rate, double start, double end,
                      const py::object& name, const py::object& motion)
    {
        vdbio::SceneGasSource g(name.is_none() ? shape.name() : name.cast<std::string>(),
                                "add_gas_source", shape);
        refuseDuplicate(mScene->gasSources, g.name, "gas source");
        g.velocity = vec3(velocity);
        g.temperature = temperature;
        g.rate = rate;
        g.start = start;
        g.end = end;
        if (!motion.is_none())
            g.motion = motionFromPython(motion, "add_gas_source('" + g.name + "')");
        mSim->addGasSource(g);
        mScene->gasSources.push_back(g);
        mInputs.gasSources.push_back(g);
    }

    std::size_t addLiquid(const sph::LevelSet& shape, const std::array<double, 3>& velocity,
                          std::optional<double> viscosity)
    {
        py::gil_scoped_release release;
        return mSim->addLiquid(shape, sph::Vec3(vec3(velocity)), viscosity);
    }

    /// Add a rigid body (a dynamic solid) of `shape` before the first step; `density` (kg/m^3)
    /// or `mass` (kg), one of them.
    void addBody(const sph::LevelSet& shape, const py::object& name, const py::object& density,
                 const py::object& mass, const std::array<double, 3>& velocity,
                 const std::array<double, 3>& angularVelocity, double restitution, double friction)
    {
        const std::string n = name.is_none() ? shape.name() : name.cast<std::string>();
        refuseDuplicate(mScene->solids, n, "body");
        if (density.is_none() == mass.is_none()) {
            throw ValueError("body '" + n + "': give density=... (kg/m^3) or mass=... (kg), "
                             + (density.is_none() ? "one of them" : "not both"));
        }
        if (mSim->stepCount() > 0) {
            throw ValueError(msg("body '", n,
                                 "': bodies are added before the first step (this "
                                 "simulation has taken ",
                                 mSim->stepCount(), ")"));
        }
        // The shape takes the body's name, which the solver's messages give.
        vdbio::SceneSolid solid(n, "add_body", sph::makeLevelSet(sph::gridOf(shape), n));
        vdbio::SceneDynamic& d = solid.dynamic.emplace();
        d.density = density.is_none() ? 0.0 : density.cast<double>();
        d.mass = mass.is_none() ? 0.0 : mass.cast<double>();
        d.velocity = vec3(velocity);
        d.angularVelocity = vec3(angularVelocity);
        d.restitution = restitution;
        d.friction = friction;
        {
            py::gil_scoped_release release;
            mSim->addSolid(solid);
        }
        mScene->solids.push_back(solid);
        mInputs.solids.push_back(solid);
    }

    /// The solid index of the body `name`, or a ValueError naming the bodies there are.
    std::size_t bodyIndex(const std::string& name) const
    {
        std::string known;
        for (std::size_t i = 0; i < mScene->solids.size(); ++i) {
            if (!mSim->body(i)) continue;
            if (mScene->solids[i].name == name) return i;
            known += (known.empty() ? "'" : ", '") + mScene->solids[i].name + "'";
        }
        throw ValueError("body '" + name + "': the simulation has no body of that name (bodies: "
                         + (known.empty() ? "none" : known) + ")");
    }

    /// The body `name` now: its state, mass properties and the liquid's push of the last step.
    py::dict body(const std::string& name) const
    {
        const std::size_t index = bodyIndex(name);
        const sph::RigidBody& b = *mSim->body(index);
        const sph::RigidBodyState& s = b.state();
        const auto [force, torque] = mSim->liquidForceOn(index);
        const sph::Quatd& q = s.orientation;
        return py::dict(
            py::arg("position") = array3(s.position),
            py::arg("orientation") = std::array<double, 4>{q.w(), q.x(), q.y(), q.z()},
            py::arg("rotation") = matrix3(b.rotation()), py::arg("velocity") = array3(s.velocity),
            py::arg("angular_velocity") = array3(b.angularVelocity()), py::arg("mass") = b.mass(),
            py::arg("volume") = b.massProperties().volume,
            py::arg("inertia") = matrix3(b.worldInertia()), py::arg("liquid_force") = array3(force),
            py::arg("liquid_torque") = array3(torque));
    }

    /// Push the body `name` with `force` (N, at its centre of mass) and `torque` (N m) over
    /// the next frame.
    void applyForce(const std::string& name, const std::array<double, 3>& force,
                    const std::array<double, 3>& torque)
    {
        const sph::Vec3d f = vec3(force), t = vec3(torque);
        if (!sph::isFinite(sph::Vec3(f)) || !sph::isFinite(sph::Vec3(t))) {
            throw ValueError("body '" + name + "': the force or torque is not finite");
        }
        mSim->addBodyForce(bodyIndex(name), f, t);
    }

    /// Replace the positions or velocities of the particles of `kind`, in the order of
    /// positions(kind).
    void setVectors(const std::string& kind, const FloatArray& values, bool positions)
    {
        const char* what = positions ? "set_positions" : "set_velocities";
        const sph::ParticleKind k = kindFromName(kind);
        const cmd::WritableParticles w = mSim->writableParticles(k);
        if (!w.set) {
            throw ValueError(msg(what, "('", kind, "'): ",
                                 k == sph::ParticleKind::Liquid || k == sph::ParticleKind::Gas
                                     ? "this scene has no such particles"
                                     : "ghost particles are made from the liquid, the gas and "
                                       "the solids every step and cannot be set; set 'liquid' or "
                                       "'gas'"));
        }
        std::vector<std::size_t> index;
        for (std::size_t i = 0; i < w.set->size(); ++i) {
            if (w.set->kinds()[i] == k && (!w.skip || (*w.skip)[i] == sph::Real(0)))
                index.push_back(i);
        }
        if (values.ndim() != 2 || values.shape(1) != 3
            || std::size_t(values.shape(0)) != index.size()) {
            throw ValueError(msg(
                what, "('", kind, "'): expected an (N, 3) array with N = ", index.size(), " (the ",
                kind, " particles now), got shape (", values.ndim() > 0 ? values.shape(0) : 0,
                values.ndim() > 1 ? msg(", ", values.shape(1)) : "", ")"));
        }
        auto a = values.unchecked<2>();
        std::vector<sph::Vec3>& out = positions ? w.set->positions() : w.set->velocities();
        for (std::size_t n = 0; n < index.size(); ++n) {
            const sph::Vec3 v(sph::Real(a(n, 0)), sph::Real(a(n, 1)), sph::Real(a(n, 2)));
            if (!sph::isFinite(v))
                throw ValueError(msg(what, "('", kind, "'): row ", n, " is not finite"));
        }
        for (std::size_t n = 0; n < index.size(); ++n)
            out[index[n]] = sph::Vec3(sph::Real(a(n, 0)), sph::Real(a(n, 1)), sph::Real(a(n, 2)));
        if (positions && w.moved) {
            py::gil_scoped_release release;
            w.moved();
        }
    }

    void onStep(const py::object& callback)
    {
        if (!PyCallable_Check(callback.ptr()))
            throw ValueError("on_step: expected a callable (sim, dt)");
        mHooks->callbacks.push_back(callback);
    }

    /// Statistics of every step since this object was made: column name -> float64 array.
    py::dict statistics() const
    {
        py::dict out;
        for (std::size_t c = 0; c < mStats->columns.size(); ++c) {
            const std::vector<double>& v = mStats->values[c];
            py::array_t<double> a(py::ssize_t(v.size()));
            std::copy(v.begin(), v.end(), a.mutable_data());
            out[py::str(mStats->columns[c])] = a;
        }
        return out;
    }

    /// Write the state to an HDF5 checkpoint, as `ghostfx run` does at its checkpoint frames,
    /// with what the script added.
    void saveCheckpoint(const std::string& path) const
    {
        vdbio::writeCheckpoint(path, mSim->saveStates(), cmd::checkpointFingerprint(*mScene),
                               mSim->frame(), python::toAttachments(mInputs));
    }

    void advanceFrame(const py::object& self)
    {
        mHooks->self = self.ptr();
        py::gil_scoped_release release;
        // The forces apply_force gave act over this frame only, however it ends.
        struct ClearForces
        {
            cmd::Simulation& sim;
            ~ClearForces() { sim.clearBodyForces(); }
        } clear{*mSim};
        mSim->beforeFrame(mSim->frame() + 1);
        mSim->advanceFrame();
    }

    /// Advance `frames` frames (default: to the scene's last frame), calling on_frame(self)
    /// after each and on_step(self, dt) after each step. Ctrl-C (KeyboardInterrupt) is raised at
    /// the end of a frame; so is ghostfx.Interrupted for SIGTERM and SIGUSR1 (where the script
    /// has not set handlers of its own), after the frame's checkpoint is written to `checkpoint`
    /// (a $F4 pattern) if given.
    void run(py::object frames, py::object onFrame, py::object checkpoint, py::object onStep,
             py::object self)
    {
        const int last = frames.is_none() ? mScene->lastFrame : mSim->frame() + frames.cast<int>();
        const cmd::StopSignals stopSignals(/*leaveHandled=*/true);
        struct RunCallback // the run's on_step, for the length of the run
        {
            StepHooks& hooks;
            ~RunCallback() { hooks.runCallback = py::object(); }
        } scoped{*mHooks};
        if (!onStep.is_none()) mHooks->runCallback = onStep;
        while (mSim->frame() < last) {
            advanceFrame(self);
            if (!onFrame.is_none()) onFrame(self);
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (const int signal = cmd::StopSignals::received()) stop(signal, checkpoint);
        }
    }

    /// After a stop signal: the frame's checkpoint (where asked for), one line on stderr as the
    /// command line prints it, and ghostfx.Interrupted (a SystemExit with code 128 + signal).
    [[noreturn]] void stop(int signal, const py::object& checkpoint) const
    {
        std::string path;
        if (!checkpoint.is_none()) {
            path = vdbio::expandFramePattern(py::str(checkpoint).cast<std::string>(), frame());
            saveCheckpoint(path);
        }
        const std::string line =
            msg("ghostfx: stopped by ", cmd::StopSignals::describe(signal), " after frame ",
                frame(),
                path.empty() ? std::string(" (no checkpoint asked for)")
                             : "; resume with ghostfx.Simulation.resume(scene, '" + path + "')");
        PySys_WriteStderr("%s\n", line.c_str());
        const py::object interrupted = py::module_::import("ghostfx").attr("Interrupted");
        const py::object where = path.empty() ? py::object(py::none()) : py::object(py::str(path));
        const py::object error = interrupted(signal, frame(), where);
        PyErr_SetObject(interrupted.ptr(), error.ptr());
        throw py::error_already_set();
    }

    int frame() const { return mSim->frame(); }
    double time() const { return mSim->time(); }
    std::uint64_t steps() const { return mSim->stepCount(); }
    std::string counts() const { return mSim->counts(); }
    py::object settings() const { return settingsOf(*mScene); }
    /// Each liquid emitter's name, cross-section (m^2) and mass rate (kg/s), scene's first.
    py::list emitterRates() const
    {
        py::list out;
        const std::vector<cmd::Simulation::EmitterRate> rates = mSim->emitterRates();
        for (std::size_t i = 0; i < rates.size() && i < mScene->emitters.size(); ++i) {
            out.append(py::dict(py::arg("name") = mScene->emitters[i].name,
                                py::arg("cross_section") = rates[i].crossSection,
                                py::arg("mass_rate") = rates[i].massRate));
        }
        return out;
    }

    py::array_t<double> positions(const std::string& kind) const
    {
        return vectors(particlesOf(*mSim, kindFromName(kind)).positions());
    }
    py::array_t<double> velocities(const std::string& kind) const
    {
        return vectors(particlesOf(*mSim, kindFromName(kind)).velocities());
    }
    /// A per-particle quantity: "density", "pressure", "mass", "id" or a named channel.
    py::array channel(const std::string& kind, const std::string& name) const
    {
        const sph::ParticleSet p = particlesOf(*mSim, kindFromName(kind), name == "mass");
        auto scalars = [](const std::vector<sph::Real>& s) {
            py::array_t<double> a(py::ssize_t(s.size()));
            auto w = a.mutable_unchecked<1>();
            for (std::size_t i = 0; i < s.size(); ++i) w(py::ssize_t(i)) = double(s[i]);
            return py::array(a);
        };
        if (name == "density") return scalars(p.densities());
        if (name == "pressure") return scalars(p.pressures());
        if (name == "mass") return scalars(p.masses());
        if (name == "id") {
            py::array_t<std::int64_t> a(py::ssize_t(p.size()));
            auto w = a.mutable_unchecked<1>();
            for (std::size_t i = 0; i < p.size(); ++i) w(py::ssize_t(i)) = std::int64_t(p.ids()[i]);
            return a;
        }
        if (p.hasScalarChannel(name)) return scalars(p.scalarChannel(name));
        if (p.hasVectorChannel(name)) return vectors(p.vectorChannel(name));
        throw ValueError("channel '" + name + "' of the " + kind
                         + " particles: not found (density, pressure, mass, id, or a solver "
                           "channel)");
    }

    /// The whitewater now by class: {"spray": {...}, "foam": {...}, "bubbles": {...}}, each
    /// with "positions", "velocities" (N, 3 float64), "ids" (int64) and "ages" (float64).
    py::dict whitewater() const
    {
        const std::optional<vdbio::WhitewaterPoints> w = mSim->whitewater();
        if (!w) {
            throw ValueError(msg("whitewater: scene '", mScene->file, "' makes none (expected "
                                 "outputs.whitewater in a liquid scene)"));
        }
        py::dict out;
        for (std::int32_t type = 0; type < 3; ++type) {
            std::vector<sph::Vec3> x, v;
            std::vector<std::int64_t> ids;
            std::vector<double> ages;
            for (std::size_t k = 0; k < w->ids.size(); ++k) {
                if (w->types[k] != type) continue;
                x.push_back(w->positions[k]);
                v.push_back(w->velocities[k]);
                ids.push_back(w->ids[k]);
                ages.push_back(double(w->ages[k]));
            }
            out[vdbio::WHITEWATER_FOG_NAMES[type]] =
                py::dict(py::arg("positions") = vectors(x), py::arg("velocities") = vectors(v),
                         py::arg("ids") = py::array_t<std::int64_t>(py::ssize_t(ids.size()),
                                                                    ids.data()),
                         py::arg("ages") = py::array_t<double>(py::ssize_t(ages.size()),
                                                               ages.data()));
        }
        return out;
    }

private:
    /// A simulation of its own copy of `scene` with `inputs` added, fresh or from `states`.
    PySimulation(std::shared_ptr<const vdbio::Scene> scene, python::ScriptInputs inputs,
                 const std::vector<sph::SolverState>* states)
        : mScene(std::make_shared<vdbio::Scene>(*scene))
        , mInputs(std::move(inputs))
    {
        auto append = [](auto& to, const auto& from) {
            to.insert(to.end(), from.begin(), from.end());
        };
        append(mScene->solids, mInputs.solids);
        append(mScene->emitters, mInputs.emitters);
        append(mScene->gasSources, mInputs.gasSources);
        mSim = cmd::makeSimulation(*mScene, states);
        for (const auto& [index, v] : mInputs.velocities) mSim->setSolidMotion(index, v.motion());
        observe();
    }

    /// The motion solid `index` follows now: the one set_solid_velocity gave it last, else its
    /// scene motion (keys, or its constant velocity).
    sph::RigidMotion motionOf(std::size_t index) const
    {
        const auto set = mInputs.velocities.find(index);
        if (set != mInputs.velocities.end()) return set->second.motion();
        const vdbio::SceneSolid& s = mScene->solids[index];
        return s.motion.keys.empty() ? sph::constantVelocity(sph::Vec3(s.velocity))
                                     : s.motion.motion();
    }

    /// The per-step statistics rows (the columns of `ghostfx run`'s stats file), collected by a
    /// step observer that holds the simulation and the table, not this object (which moves);
    /// then the script's on_step callbacks.
    struct StatsTable
    {
        std::vector<std::string> columns;
        std::vector<std::vector<double>> values; ///< values[c][step]
    };
    void observe()
    {
        cmd::Simulation* sim = mSim.get();
        std::shared_ptr<StatsTable> table = mStats;
        std::shared_ptr<StepHooks> hooks = mHooks;
        mSim->setStepObserver([sim, table, hooks](double dt) {
            const vdbio::StatsRow row = sim->statsRow(sim->frame() + 1, dt);
            if (table->columns.empty()) {
                for (const auto& [name, value] : row.values) table->columns.push_back(name);
                table->values.resize(table->columns.size());
            }
            for (std::size_t c = 0; c < row.values.size() && c < table->values.size(); ++c) {
                table->values[c].push_back(row.values[c].second);
            }
            hooks->call(dt);
        });
    }

    std::shared_ptr<vdbio::Scene> mScene; ///< the scene with what the script added
    python::ScriptInputs mInputs;         ///< what the script added, for checkpoints
    std::unique_ptr<cmd::Simulation> mSim;
    std::shared_ptr<StatsTable> mStats = std::make_shared<StatsTable>();
    std::shared_ptr<StepHooks> mHooks = std::make_shared<StepHooks>();
};

using PySimulationClass = py::class_<PySimulation>;

/// Simulation: making, advancing, running and checkpointing.
void bindRunning(PySimulationClass& c)
{
    c.def(py::init<const PyScene&>(), py::arg("scene"))
        .def(
            "advance_frame", [](py::object self) { self.cast<PySimulation&>().advanceFrame(self); },
            "Simulate one frame (the scene's substeps or CFL steps); releases the GIL")
        .def(
            "run",
            [](py::object self, py::object frames, py::object onFrame, py::object checkpoint,
               py::object onStep) {
        self.cast<PySimulation&>().run(frames, onFrame, checkpoint, onStep, self);
            },
            py::arg("frames") = py::none(), py::arg("on_frame") = py::none(),
            py::arg("checkpoint") = py::none(), py::arg("on_step") = py::none(),
            "Advance `frames` frames (default: to the scene's last), calling on_frame(sim) after "
            "each frame and on_step(sim, dt) after each step (besides the callbacks of "
            "sim.on_step). An exception raised by a callback stops the run after the complete "
            "step and propagates. Ctrl-C stops at the end of a frame with KeyboardInterrupt. "
            "SIGTERM and SIGUSR1 (a render farm's stop) finish the frame, call on_frame, write "
            "the frame's checkpoint to `checkpoint` (a path pattern such as "
            "'out/checkpoint.$F4.h5') if given, and raise ghostfx.Interrupted, a SystemExit whose "
            "code is 128 + the signal (143, 138)")
        .def("on_step", &PySimulation::onStep, py::arg("callback"),
             "Call callback(sim, dt) after every step from now on (dt in s), in advance_frame() "
             "and run() alike; an exception it raises stops the frame after the complete step "
             "and propagates")
        .def("write_frame", &PySimulation::writeFrame, py::arg("folder") = py::none(),
             "Write the scene's outputs for the current frame (files named by the scene's "
             "`outputs`, as `ghostfx run` writes them) into `folder` (default: "
             "outputs.directory); releases the GIL. Added solids are drawn in the preview")
        .def("statistics", &PySimulation::statistics,
             "Per-step statistics since this object was made, as `ghostfx run` writes them to "
             "stats.h5: a dict of column name -> float64 array, one entry per step")
        .def("save_checkpoint", &PySimulation::saveCheckpoint, py::arg("path"),
             "Write the state to an HDF5 checkpoint (the format of `ghostfx run`), with the "
             "solids, emitters and gas sources the script added and the solid velocities it set")
        .def_static("resume", &PySimulation::resume, py::arg("scene"), py::arg("path"),
                    "A simulation continuing from a checkpoint of the same scene settings, with "
                    "what the script had added (nothing to add again); it continues bit for bit "
                    "as the run that wrote it");
}

/// Simulation: what a script adds and sets.
void bindScripting(PySimulationClass& c)
{
    const auto zero = std::array<double, 3>{0, 0, 0};
    const double never = std::numeric_limits<double>::infinity();
    c.def("set_solid_velocity", &PySimulation::setSolidVelocity, py::arg("name"),
          py::arg("velocity"),
          "From now on the solid `name` (the scene's or an added one) moves at `velocity` (m/s) "
          "from where it is, without turning. It must be a moving solid (a velocity or motion "
          "keys); saved in checkpoints")
        .def("solid_placement", &PySimulation::solidPlacement, py::arg("name"),
             "(rotation, translation): where the solid `name` is now, its level set's frame "
             "placed as x_world = rotation @ x + translation (m), as the preview draws it. "
             "Liquid scenes")
        .def("add_solid", &PySimulation::addSolid, py::arg("level_set"), py::arg("velocity") = zero,
             py::arg("name") = py::none(), py::arg("motion") = py::none(),
             "Add a solid beside the scene's, as a scene solid: static, or placed at level set + "
             "velocity t (t from 0 s), or by `motion`, the keys of a scene solid's motion "
             "([{'time': 0, 'translate': [x, y, z], 'rotate': [rx, ry, rz]}, ...]). `name` "
             "(default: the level set's) must be new; set_solid_velocity finds it, previews draw "
             "it, checkpoints keep it. Its ghosts are sampled now. Liquid scenes")
        .def("add_liquid", &PySimulation::addLiquid, py::arg("level_set"),
             py::arg("velocity") = zero, py::arg("viscosity") = py::none(),
             "Sample a liquid body into the simulation before its first frame; returns the "
             "particles added. `viscosity` (m^2/s) is its own, in settings.viscosity's range "
             "(default: settings.viscosity). Liquid scenes")
        .def("add_emitter", &PySimulation::addEmitter, py::arg("level_set"), py::arg("velocity"),
             py::arg("start") = 0.0, py::arg("end") = never, py::arg("name") = py::none(),
             py::arg("motion") = py::none(), py::arg("viscosity") = py::none(),
             "Add a liquid emitter, as a scene emitter: from `start` to `end` (s) its volume is "
             "kept full of liquid moving at `velocity` (m/s, in the emitter's own frame), pouring "
             "rho0 |velocity| times its cross-section in kg/s. `motion`: keys as add_solid's, "
             "moving and turning the emitter (a sweeping hose); the liquid leaves at `velocity` "
             "turned with it plus the emitter's own velocity. `viscosity` (m^2/s): the new "
             "liquid's own. Kept in checkpoints. Liquid scenes")
        .def("add_gas_source", &PySimulation::addGasSource, py::arg("level_set"),
             py::arg("velocity") = zero, py::arg("temperature") = 373.15, py::arg("rate") = 0.0,
             py::arg("start") = 0.0, py::arg("end") = never, py::arg("name") = py::none(),
             py::arg("motion") = py::none(),
             "Add a gas source, as a scene gas source (`motion`: keys as add_solid's, a moving "
             "source): from `start` to `end` (s) its volume is "
             "kept full of gas at `temperature` (K) moving at `velocity` (m/s), at most `rate` "
             "particles per second (0: as many as fit). Kept in checkpoints. Gas scenes and the "
             "vapour of boiling ones");
}

/// Simulation: the particles a script sets.
void bindSetters(PySimulationClass& c)
{
    c.def(
            "set_positions",
            [](PySimulation& s, const std::string& kind, const FloatArray& v) {
        s.setVectors(kind, v, true);
            },
            py::arg("kind"), py::arg("positions"),
            "Replace the positions (m) of the particles of `kind` ('liquid' or 'gas'), an (N, 3) "
            "array in the order of positions(kind); the next step searches neighbours anew. "
            "Ghosts ('air', 'solid', 'boundary') are made from the rest and cannot be set")
        .def(
            "set_velocities",
            [](PySimulation& s, const std::string& kind, const FloatArray& v) {
        s.setVectors(kind, v, false);
            },
            py::arg("kind"), py::arg("velocities"),
            "Replace the velocities (m/s) of the particles of `kind` ('liquid' or 'gas'), an "
            "(N, 3) array in the order of positions(kind)");
}

/// Simulation: rigid bodies (dynamic solids) a script adds, reads and pushes.
void bindBodies(PySimulationClass& c)
{
    const auto zero = std::array<double, 3>{0, 0, 0};
    c.def("add_body", &PySimulation::addBody, py::arg("level_set"), py::arg("name") = py::none(),
          py::arg("density") = py::none(), py::arg("mass") = py::none(), py::arg("velocity") = zero,
          py::arg("angular_velocity") = zero, py::arg("restitution") = 0.2,
          py::arg("friction") = 0.5,
          "Add a rigid body (a dynamic solid) beside the scene's solids, before the first "
          "step: the level set filled with `density` (kg/m^3) or of total `mass` (kg), one of "
          "them, starting at `velocity` (m/s, its centre of mass) and `angular_velocity` "
          "(rad/s); gravity, the liquid and its contacts (`restitution` 0 to 1, Coulomb "
          "`friction`) move it. `name` (default: the level set's) must be new; body() reads "
          "it, apply_force pushes it, previews draw it, checkpoints keep it. Liquid scenes "
          "(method ghost)")
        .def("apply_force", &PySimulation::applyForce, py::arg("name"), py::arg("force"),
             py::arg("torque") = zero,
             "Push the body `name` with `force` (N, world axes, at its centre of mass) and "
             "`torque` (N m, about its centre of mass) in every step of the next frame (of the "
             "frame in progress, called from on_step); it adds to gravity and the liquid's "
             "force and is cleared when that frame ends. Calls add up. Checkpoints do not keep "
             "it")
        .def(
            "apply_torque",
            [](PySimulation& s, const std::string& name, const std::array<double, 3>& torque) {
        s.applyForce(name, {0, 0, 0}, torque);
            },
            py::arg("name"), py::arg("torque"),
            "apply_force(name, (0, 0, 0), torque): a torque (N m, world axes) over the next "
            "frame")
        .def("body", &PySimulation::body, py::arg("name"),
             "The rigid body (dynamic solid) `name` now, a dict: position (its centre of "
             "mass, m), orientation (unit quaternion w, x, y, z turning its level set's frame "
             "into the world), rotation (the same as a 3x3 array), velocity (m/s), "
             "angular_velocity (rad/s), mass (kg), volume (m^3), inertia (3x3, kg m^2, world "
             "axes, about the centre of mass), liquid_force (N) and liquid_torque (N m, about "
             "the centre of mass): what the liquid gave it in the last step");
}

/// Simulation: what a script reads.
void bindReading(PySimulationClass& c)
{
    c.def_property_readonly("frame", &PySimulation::frame, "frames advanced so far")
        .def_property_readonly("time", &PySimulation::time, "simulated time (s)")
        .def_property_readonly("steps", &PySimulation::steps, "steps taken so far")
        .def_property_readonly("counts", &PySimulation::counts,
                               "particle counts, as the log prints")
        .def_property_readonly("settings", &PySimulation::settings,
                               "the scene's `settings` object (after overrides) as a dict, a copy")
        .def("emitter_rates", &PySimulation::emitterRates,
             "Each liquid emitter (the scene's, then the added ones) as a dict: name, "
             "cross_section (m^2, its shadow along its velocity) and mass_rate (kg/s, rho0 "
             "|velocity| cross_section); empty where the scene's solver has none")
        .def("positions", &PySimulation::positions, py::arg("kind") = "liquid",
             "Positions (m) of the particles of `kind` ('liquid', 'air', 'solid', 'gas', "
             "'boundary'), an (N, 3) float64 copy")
        .def("velocities", &PySimulation::velocities, py::arg("kind") = "liquid",
             "Velocities (m/s), an (N, 3) float64 copy")
        .def("whitewater", &PySimulation::whitewater,
             "The whitewater now (scenes with outputs.whitewater), by class: a dict with "
             "'spray', 'foam' and 'bubbles', each a dict of 'positions' and 'velocities' "
             "((N, 3) float64, m and m/s), 'ids' (int64) and 'ages' (float64, s), copies")
        .def("channel", &PySimulation::channel, py::arg("kind"), py::arg("name"),
             "A per-particle quantity ('density', 'pressure', 'mass', 'id' or a solver channel), "
             "a copy. Before the first step 'mass' is the mass the first step gives (the mass "
             "scaling's, measured apart)");
}

void bindSimulation(py::module_& m)
{
    PySimulationClass c(m, "Simulation",
                        "The solvers a scene needs (liquid, gas or boiling), as `ghostfx run` "
                        "builds them");
    bindRunning(c);
    bindScripting(c);
    bindSetters(c);
    bindBodies(c);
    bindReading(c);
}

} // namespace

PYBIND11_MODULE(_ghostfx, m)
{
    m.doc() = "ghostfx: Ghost SPH liquids and fast SPH gases on OpenVDB (the C++ library behind "
              "the ghostfx command line)";
    openvdb::initialize();

    // The library's errors carry one-line messages meant for users: keep the text, map the
    // kind to the Python exception a script expects.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const IoError& e) {
            PyErr_SetString(PyExc_OSError, e.what());
        } catch (const NumericalError& e) {
            PyErr_SetString(PyExc_ArithmeticError, e.what());
        } catch (const Error& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        }
    });

    py::class_<PyScene>(m, "Scene", "A scene read from a JSON file (or a role-tagged .vdb)")
        .def_property_readonly("file", [](const PyScene& s) { return s.scene->file; })
        .def_property_readonly("method", [](const PyScene& s) { return s.scene->method; })
        .def_property_readonly("spacing", [](const PyScene& s) { return s.scene->spacing; })
        .def_property_readonly("frame_rate", [](const PyScene& s) { return s.scene->frameRate; })
        .def_property_readonly(
            "frame_range",
            [](const PyScene& s) {
        return std::make_pair(s.scene->firstFrame, s.scene->lastFrame);
            })
        .def_property_readonly(
            "settings", [](const PyScene& s) { return settingsOf(*s.scene); },
            "the `settings` object (after overrides) as a dict, a copy");

    m.def(
        "load_scene",
        [](const std::string& path, py::object overrides) {
        auto scene =
            std::make_shared<const vdbio::Scene>(vdbio::readScene(path, assignments(overrides)));
        // Every solver key too, as `ghostfx run` checks them before sampling anything.
        cmd::checkSimulationSettings(*scene);
        return PyScene{scene};
        },
        py::arg("path"), py::arg("overrides") = py::none(),
        "Read a scene. `overrides` is a dict of the dotted keys of the command line's -D, e.g. "
        "{'settings.stiffness': 5000}. A bad scene raises ValueError with the command line's "
        "message; a file that cannot be read raises OSError.");

    bindSimulation(m);

    py::class_<sph::LevelSet>(m, "LevelSet",
                              "A narrow-band signed-distance grid (OpenVDB), negative inside")
        .def_static(
            "from_array", &levelSetFromArray, py::arg("sdf"), py::arg("voxel_size"),
            py::arg("origin") = std::array<double, 3>{0, 0, 0}, py::arg("name") = "array",
            "From a dense array sdf[i, j, k] of signed distances (m) at origin + voxel_size "
            "(i, j, k); the band within 3 voxels of the surface is kept")
        .def_static(
            "from_vdb",
            [](const std::string& file, const std::string& grid) {
        return vdbio::loadLevelSet(file, grid, "LevelSet.from_vdb");
            },
            py::arg("file"), py::arg("grid"), "The level-set grid `grid` of a .vdb file")
        .def("to_array", &levelSetToArray,
             "(values, origin): the signed distances over the box of active voxels, float32, and "
             "the world position of values[0, 0, 0]")
        .def(
            "phi",
            [](const sph::LevelSet& shape,
               const py::array_t<double, py::array::c_style | py::array::forcecast>& points) {
        if (points.ndim() != 2 || points.shape(1) != 3) {
            throw ValueError("LevelSet.phi: expected an (N, 3) array of points");
        }
        auto p = points.unchecked<2>();
        py::array_t<double> out(points.shape(0));
        auto w = out.mutable_unchecked<1>();
        for (py::ssize_t i = 0; i < p.shape(0); ++i) {
            w(i) = double(
                shape.phi(sph::Vec3(sph::Real(p(i, 0)), sph::Real(p(i, 1)), sph::Real(p(i, 2)))));
        }
        return out;
            },
            py::arg("points"), "Signed distance (m) at each of the (N, 3) points, trilinear")
        .def_property_readonly("voxel_size",
                               [](const sph::LevelSet& s) { return double(s.voxelSize()); })
        .def_property_readonly("name", &sph::LevelSet::name);

    m.def("sample", &poissonSamples, py::arg("level_set"), py::arg("spacing"), py::arg("seed") = 1,
          "Poisson-disk samples ([SB12] Sec. 4.5) of a LevelSet at particle spacing `spacing` (m): "
          "an (N, 3) float64 array");
    m.def(
        "sample",
        [](const std::string& file, const std::string& grid, double spacing, std::uint64_t seed) {
        return poissonSamples(vdbio::loadLevelSet(file, grid, "sample"), spacing, seed);
        },
        py::arg("file"), py::arg("grid"), py::arg("spacing"), py::arg("seed") = 1,
        "Poisson-disk samples ([SB12] Sec. 4.5) of the level set `grid` in the .vdb `file` at "
        "particle spacing `spacing` (m): an (N, 3) float64 array");

    m.def(
        "set_sample_cache",
        [](const std::string& folder) {
        cmd::setProcessSampleCache(folder);
        if (!folder.empty()) cmd::processSampleCache(); // the folder's errors now, not later
        },
        py::arg("folder"),
        "Keep the Poisson-disk samples of solids and liquid bodies in `folder` and take them from "
        "it when the same shape is sampled again (as `ghostfx run --sample-cache`): the same "
        "results, bit for bit, without sampling again. \"off\" or \"\" turns it off. When no "
        "folder was set: $GHOSTFX_SAMPLE_CACHE, else the per-user folder "
        "($XDG_CACHE_HOME/ghostfx/samples or ~/.cache/ghostfx/samples, kept within "
        "$GHOSTFX_SAMPLE_CACHE_LIMIT_MB, 2048 MiB).");
    m.def(
        "sample_cache_counts",
        []() {
        const vdbio::SampleCache* cache = cmd::processSampleCache();
        return py::make_tuple(cache ? cache->hits() : 0, cache ? cache->stored() : 0);
        },
        "(shapes loaded, shapes sampled and kept) by this process's sample cache so far");

    bindReaders(m);
    m.attr("__version__") = GHOSTFX_VERSION;
}
