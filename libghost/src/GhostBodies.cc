/// @file   GhostBodies.cc
/// @brief  Dynamic solids: rigid bodies two-way coupled to the liquid through their ghost
///         particles ([SB12] Sec. 4.4's ghost solids), with level-set contact between them and
///         the other solids.
/// @details A dynamic solid is a moving solid whose motion is its body's state
///          (RigidBody::placementAt), so its ghosts are sampled, re-placed and extrapolated as
///          any moving solid's and both pressure models see it as one. Each step:
///           1. the model's forces (PressureSolver::solidPairPressure) and the wall drag of
///              XSPH (Eq. 2 with GhostSettings::solidEpsilonForStep) between each liquid
///              particle and the body's ghosts are summed, reversed, into a force and a torque
///              about the centre of mass (gatherBodyForces, before the particles move);
///           2. the body takes that force with gravity and any force a caller adds, touches the
///              other solids and bodies (sph::resolveContact) and moves (advanceBodies);
///           3. its ghosts go where it is (moveSolids), and the liquid particles the collision
///              projection pushes out of it give it the momentum they lose.
///          Every sum over particles is reduced in index order (parallel::reduceInOrder), so
///          any thread count gives the same bodies.
///
///          Coupling a light body explicitly (the force of this step's pressure, which answered
///          last step's body velocity) diverges through the added mass where the liquid is
///          incompressible: the liquid the body must push aside answers its acceleration of one
///          step with a force of m_a a the next, and when m_a exceeds the body's mass m the
///          response overshoots and grows (a floating box of density 100 has m_a of several m).
///          The liquid's force is therefore taken through the added-mass filter of partitioned
///          fluid-structure coupling (e.g. Förster, Wall and Ramm 2007, CMAME 196): with an
///          estimate m~ of the added mass, (m + m~) a_{n+1} = F_{n+1} + m~ a_n, applied as
///              F'_{n+1} = (F_{n+1} + J_n / dt) / (1 + r),   J_{n+1} = r dt F'_{n+1},
///          r = m~ / m, J the impulse gathered and not yet applied (the same for the torque).
///          It is stable while the true added mass is below m + 2 m~, it leaves a steady force
///          (floating, resting, a constant push) exact, and every impulse the liquid gives is
///          applied once: the body's momentum lags by J, which vanishes when the push ends.
///          m~ is PressureSolver::addedMassShare() times rho0 V times the share of the body's
///          ghosts the liquid reaches (a body out of the liquid falls freely): 2 for DFSPH,
///          whose solve treats the body's ghosts as moving at the body's velocity at the step's
///          start (the filter gives it the stability that taking the body into the solve,
///          Gissler et al. 2019, would, at no cost in the solve); 0 for the Tait step, whose
///          liquid answers through pressure waves that its acoustic step resolves. In the Tait
///          step a body's ghosts take no pressure of their own (GhostSolver::bodyGhostFlags),
///          so the pair force is the gradient of the liquid's energy.
///
///          A dynamic solid's ghosts are sampled half a spacing inside its surface
///          (sph::erodedLevelSet), so the liquid's boundary lies on the body's surface.
#include "ghostfx/ghost/GhostSolver.h"

#include "GhostInternal.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/MassProperties.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/RigidContact.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>
#include <vector>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

namespace {

/// The state keys of a body in SolverState::reals: "body_E_x", ... (E the solid's index).
/// The state (centre, quaternion, velocity, angular momentum), the filter's liquid force and
/// torque, the mass properties, and the filter's withheld impulse and angular impulse (kept, not found again from the shape: a shape read back
/// from a script's attachment can differ in its last bits, and the run with it).
constexpr const char* BODY_KEYS[] = {
    "x",   "y",   "z",   "qw",  "qx",  "qy",  "qz",   "vx",     "vy", "vz", "lx", "ly",  "lz",
    "fx",  "fy",  "fz",  "tx",  "ty",  "tz",  "mass", "volume", "cx", "cy", "cz", "ixx", "ixy",
    "ixz", "iyx", "iyy", "iyz", "izx", "izy", "izz",  "jx",     "jy", "jz", "hx", "hy",  "hz"};
constexpr std::size_t BODY_VALUES = sizeof(BODY_KEYS) / sizeof(BODY_KEYS[0]);

std::string bodyKey(std::size_t solid, const char* key)
{
    return "body_" + std::to_string(solid) + "_" + key;
}

/// A force and a torque, summed.
struct Wrench
{
    Vec3d force{0.0}, torque{0.0};
};

/// The mass properties a DynamicSolid's density or mass gives `shape`.
MassProperties bodyMassProperties(const LevelSet& shape, const DynamicSolid& spec)
{
    const std::string& name = shape.name();
    const bool byDensity = spec.density > 0, byMass = spec.mass > 0;
    if (byDensity == byMass || !std::isfinite(spec.density) || !std::isfinite(spec.mass)
        || spec.density < 0 || spec.mass < 0) {
        throw ValueError(msg("dynamic solid '", name, "': density ", spec.density,
                             " kg/m^3 and mass ", spec.mass,
                             " kg: expected exactly one of them, finite and > 0"));
    }
    MassProperties p = massProperties(shape, byDensity ? spec.density : 1.0);
    if (byMass) {
        const double scale = spec.mass / p.mass;
        p.mass = spec.mass;
        p.inertia *= scale;
    }
    return p;
}

void checkMaterial(const std::string& name, const DynamicSolid& spec)
{
    const RigidBodyMaterial& m = spec.material;
    if (!(m.restitution >= 0 && m.restitution <= 1)) {
        throw ValueError(
            msg("dynamic solid '", name, "': restitution ", m.restitution, ": expected 0 to 1"));
    }
    if (!(m.friction >= 0) || !std::isfinite(m.friction)) {
        throw ValueError(msg("dynamic solid '", name, "': friction ", m.friction,
                             ": expected a finite value >= 0"));
    }
    if (!isFinite(Vec3(spec.velocity)) || !isFinite(Vec3(spec.angularVelocity))) {
        throw ValueError(
            msg("dynamic solid '", name, "': velocity or angular velocity is not finite"));
    }
}

} // namespace

std::size_t GhostSolver::addDynamicSolid(const LevelSet& solid, const DynamicSolid& spec)
{
    const std::string& name = solid.name();
    if (mSettings.method != Method::Ghost) {
        throw ValueError(msg("dynamic solid '", name,
                             "': dynamic solids need method 'ghost', not '",
                             methodName(mSettings.method), "'"));
    }
    if (mExchange) {
        throw ValueError(msg("dynamic solid '", name,
                             "': dynamic solids run on one process; run this scene without MPI"));
    }
    checkMaterial(name, spec);
    auto body = std::make_unique<Body>(RigidBody(bodyMassProperties(solid, spec), spec.material));
    RigidBodyState state = body->rigid.state();
    state.time = mRun.time;
    body->rigid.setState(state);
    body->rigid.setVelocity(spec.velocity);
    body->rigid.setAngularVelocity(spec.angularVelocity);
    const std::size_t index = mSolids.size();
    if (index < mRestoredSolids) restoreBody(*body, index, name);
    Body* raw = body.get();
    RigidMotion motion = [raw](double t) { return raw->rigid.placementAt(t); };
    addSolidBody(solid, std::move(motion), true, std::move(body));
    findContactPoints(index);
    return index;
}

void GhostSolver::restoreBody(Body& body, std::size_t index, const std::string& name) const
{
    if (index >= mRestoredBodies.size() || mRestoredBodies[index].empty()) {
        throw ValueError(msg("restoreState: solid ", index, " ('", name,
                             "') is dynamic here but was not in the saved run"));
    }
    const std::vector<double>& v = mRestoredBodies[index];
    MassProperties p;
    p.mass = v[19];
    p.volume = v[20];
    p.centre = Vec3d(v[21], v[22], v[23]);
    // All nine: the sums give the tensor symmetric only to rounding.
    p.inertia = Mat3d(v[24], v[25], v[26], v[27], v[28], v[29], v[30], v[31], v[32]);
    body.rigid = RigidBody(p, body.rigid.material());
    RigidBodyState restored;
    restored.position = Vec3d(v[0], v[1], v[2]);
    restored.orientation = Quatd(v[4], v[5], v[6], v[3]);
    restored.velocity = Vec3d(v[7], v[8], v[9]);
    restored.angularMomentum = Vec3d(v[10], v[11], v[12]);
    restored.time = mRun.time;
    body.rigid.setState(restored);
    body.liquidForce = Vec3d(v[13], v[14], v[15]);
    body.liquidTorque = Vec3d(v[16], v[17], v[18]);
    body.withheldImpulse = Vec3d(v[33], v[34], v[35]);
    body.withheldAngularImpulse = Vec3d(v[36], v[37], v[38]);
}

bool GhostSolver::isDynamic(std::size_t solidIndex) const
{
    return solidIndex < mSolids.size() && mSolids[solidIndex]->body != nullptr;
}

GhostSolver::Body& GhostSolver::bodyOf(std::size_t solidIndex) const
{
    if (!isDynamic(solidIndex)) {
        throw ValueError(
            msg("solid ", solidIndex, " is not a dynamic solid (", mSolids.size(), " solids)"));
    }
    return *mSolids[solidIndex]->body;
}

const RigidBody& GhostSolver::body(std::size_t solidIndex) const
{
    return bodyOf(solidIndex).rigid;
}

void GhostSolver::addBodyForce(std::size_t solidIndex, const Vec3d& force, const Vec3d& torque)
{
    if (!isFinite(Vec3(force)) || !isFinite(Vec3(torque))) {
        throw ValueError(msg("solid ", solidIndex, ": the force or torque added is not finite"));
    }
    Body& b = bodyOf(solidIndex);
    b.externalForce += force;
    b.externalTorque += torque;
}

void GhostSolver::clearBodyForces()
{
    for (const auto& solid : mSolids) {
        if (!solid->body) continue;
        solid->body->externalForce = Vec3d(0.0);
        solid->body->externalTorque = Vec3d(0.0);
    }
}

std::pair<Vec3d, Vec3d> GhostSolver::liquidForceOn(std::size_t solidIndex) const
{
    const Body& b = bodyOf(solidIndex);
    return {b.liquidForce, b.liquidTorque};
}

void GhostSolver::findContactPoints(std::size_t solidIndex)
{
    // The surface layer of the band (its ghosts half a spacing deep, sampleSolid), moved out
    // along their normals onto the surface.
    Body& b = bodyOf(solidIndex);
    const ParticleSet& set = mMoving.block.particles();
    const auto& index = set.scalarChannel(SOLID_INDEX);
    const auto& local = set.vectorChannel(SOLID_LOCAL);
    const auto& normal = set.vectorChannel(SOLID_LOCAL_NORMAL);
    const LevelSet& shape = mSolids[solidIndex]->shape;
    const Real h = mSettings.spacing;
    b.contactPoints.clear();
    b.ghosts = 0;
    b.radius = 0;
    for (std::size_t s = 0; s < set.size(); ++s) {
        if (std::size_t(index[s]) != solidIndex) continue;
        ++b.ghosts;
        const Vec3 onSurface = local[s] + (Real(0.5) * h) * normal[s];
        if (!(std::abs(shape.phi(onSurface)) < Real(0.25) * h)) continue;
        b.contactPoints.push_back(Vec3d(onSurface));
        b.radius = std::max(b.radius, (Vec3d(onSurface) - b.rigid.localCentre()).length());
    }
    // In an order of their own (the contact impulses are sequential): the block's order differs
    // between a fresh run and a restored one.
    std::sort(b.contactPoints.begin(), b.contactPoints.end(), [](const Vec3d& p, const Vec3d& q) {
        return p[0] != q[0] ? p[0] < q[0] : p[1] != q[1] ? p[1] < q[1] : p[2] < q[2];
    });
}

void GhostSolver::saveBodies(SolverState& state) const
{
    for (std::size_t e = 0; e < mSolids.size(); ++e) {
        const Body* b = mSolids[e]->body.get();
        if (!b) continue;
        const RigidBodyState& s = b->rigid.state();
        const Quatd& q = s.orientation;
        const MassProperties& p = b->rigid.massProperties();
        // In BODY_KEYS' order.
        std::vector<double> values;
        auto put = [&values](std::initializer_list<double> v) { values.insert(values.end(), v); };
        auto putVector = [&put](const Vec3d& v) { put({v[0], v[1], v[2]}); };
        putVector(s.position);
        put({q.w(), q.x(), q.y(), q.z()});
        putVector(s.velocity);
        putVector(s.angularMomentum);
        putVector(b->liquidForce);
        putVector(b->liquidTorque);
        put({p.mass, p.volume});
        putVector(p.centre);
        for (int r = 0; r < 3; ++r)
            putVector(Vec3d(p.inertia(r, 0), p.inertia(r, 1), p.inertia(r, 2)));
        putVector(b->withheldImpulse);
        putVector(b->withheldAngularImpulse);
        for (std::size_t k = 0; k < BODY_VALUES; ++k)
            state.reals[bodyKey(e, BODY_KEYS[k])] = values[k];
    }
}

void GhostSolver::readRestoredBodies(const SolverState& state)
{
    // A solid with the first key has them all (a state missing one is refused here).
    const std::int64_t solids = state.count("solids");
    std::vector<std::vector<double>> bodies(static_cast<std::size_t>(solids));
    for (std::int64_t e = 0; e < solids; ++e) {
        if (!state.reals.count(bodyKey(std::size_t(e), BODY_KEYS[0]))) continue;
        for (const char* key : BODY_KEYS)
            bodies[std::size_t(e)].push_back(state.real(bodyKey(std::size_t(e), key)));
    }
    mRestoredBodies = std::move(bodies);
}

} // namespace ghost
} // namespace ghostfx
