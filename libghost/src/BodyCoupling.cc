/// @file   BodyCoupling.cc
/// @brief  The step of the dynamic solids (GhostBodies.cc's file comment): the liquid's force
///         on each body, the added-mass filter, contacts, the motion, and the momentum of the
///         collision projection.
#include "ghostfx/ghost/GhostSolver.h"

#include "GhostInternal.h"

#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/RigidContact.h>

#include <algorithm>
#include <cmath>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

namespace {

struct Wrench
{
    Vec3d force{0.0}, torque{0.0};
};

void addWrenches(std::vector<Wrench>& total, const std::vector<Wrench>& part)
{
    for (std::size_t b = 0; b < total.size(); ++b) {
        total[b].force += part[b].force;
        total[b].torque += part[b].torque;
    }
}

} // namespace

bool GhostSolver::hasBodies() const
{
    return std::any_of(mSolids.begin(), mSolids.end(), [](const auto& s) { return bool(s->body); });
}

std::vector<int> GhostSolver::bodySlots() const
{
    std::vector<int> slot(mSolids.size(), -1);
    int next = 0;
    for (std::size_t e = 0; e < mSolids.size(); ++e) {
        if (mSolids[e]->body) slot[e] = next++;
    }
    return slot;
}

std::vector<Vec3d> GhostSolver::bodyCentres(const std::vector<int>& slot) const
{
    std::vector<Vec3d> centre;
    for (std::size_t e = 0; e < mSolids.size(); ++e) {
        if (slot[e] >= 0) centre.push_back(mSolids[e]->body->rigid.state().position);
    }
    return centre;
}

void GhostSolver::gatherBodyForces(Real dt)
{
    // Each pair of a liquid particle i and a body's ghost s pushed i by the model's pressure
    // force -m_i M (c k_i + k_s) grad W_is and dragged it by XSPH's eps M / rho_s W_is
    // (v*_s - v*_i) per step; the body takes the reverse of both.
    const std::vector<int> slot = bodySlots();
    const std::size_t bodies = std::size_t(*std::max_element(slot.begin(), slot.end()) + 1);
    SolidPairPressure terms;
    LiquidStep step(*this);
    mPressure->solidPairPressure(step, terms);
    const ParticleSet& solids = mMoving.block.particles();
    const auto& xs = solids.positions();
    const auto& rhoS = solids.densities();
    const auto& pS = solids.pressures();
    const auto& vS = solids.velocities();
    const auto& index = solids.scalarChannel(SOLID_INDEX);
    const auto& x = mParticles.positions();
    const auto& m = mParticles.masses();
    const auto& kind = mParticles.kinds();
    const auto& vstar = mParticles.vectorChannel(VSTAR);
    const double M = mMass, rho0 = mSettings.restDensity, share = terms.share;
    const Real epsSolid = mSettings.solidEpsilonForStep(dt, fastestOwnedLiquid());
    const Vec3 g = mSettings.gravity;
    const std::vector<Vec3d> centre = bodyCentres(slot);
    auto solidTerm = [&](Index s, std::size_t i) -> double {
        if (terms.solid == SolidPairPressure::SolidTerm::Own) return double(pS[s] / sqr(rhoS[s]));
        if (terms.solid != SolidPairPressure::SolidTerm::Mirror) return 0.0;
        const Vec3& gs = terms.wallGravity ? (*terms.wallGravity)[s] : g;
        return double(gs.dot(xs[s] - x[i])) / rho0;
    };
    const std::vector<Wrench> totals = parallel::reduceInOrder(
        0, mParticles.size(), std::vector<Wrench>(bodies),
        [&](std::size_t i, std::vector<Wrench>& acc) {
        if (kind[i] != ParticleKind::Liquid) return;
        for (Index s : mMoving.lists[i]) {
            const int b = slot[std::size_t(index[s])];
            const Vec3 d = x[i] - xs[s];
            const Real r = d.length();
            if (b < 0 || !(r > Real(0))) continue;
            const double k = share * double(terms.liquid[i]) + solidTerm(s, i);
            Vec3d f = Vec3d(d) * (double(m[i]) * M * k * double(mKernel.gradFactor(r)));
            f -= Vec3d(vS[s] - vstar[i])
                 * (double(m[i]) * double(epsSolid) * M / double(rhoS[s]) * double(mKernel.W(r))
                    / double(dt));
            acc[std::size_t(b)].force += f;
            acc[std::size_t(b)].torque += (Vec3d(xs[s]) - centre[std::size_t(b)]).cross(f);
        }
        },
        addWrenches, 512);
    for (std::size_t e = 0; e < mSolids.size(); ++e) {
        if (slot[e] < 0) continue;
        mSolids[e]->body->gatheredForce = totals[std::size_t(slot[e])].force;
        mSolids[e]->body->gatheredTorque = totals[std::size_t(slot[e])].torque;
    }
}

void GhostSolver::measureWetShares(const std::vector<int>& slot)
{
    // The share of each body's ghosts the liquid reached: the added mass's share.
    const auto& index = mMoving.block.particles().scalarChannel(SOLID_INDEX);
    std::vector<std::size_t> wet(mSolids.size(), 0);
    for (Index s : mMoving.touched) ++wet[std::size_t(index[s])];
    for (std::size_t e = 0; e < mSolids.size(); ++e) {
        if (slot[e] < 0) continue;
        Body& body = *mSolids[e]->body;
        body.wetShare = body.ghosts ? double(wet[e]) / double(body.ghosts) : 0.0;
    }
}

void GhostSolver::advanceBodies(Real dt)
{
    // The added-mass filter (GhostBodies.cc): F' = (F + J / dt) / (1 + r), r = m~ / m, with J
    // the impulse withheld so far; J then becomes r dt F'. With a constant r and dt this is
    // F' = (F + r F'_last) / (1 + r); as r follows the wet share, every impulse the liquid
    // gave is applied once (keeping F'_last instead lost (r_n - r_n-1) dt F' each step: 1.6 %
    // of a ball's momentum as it splashed over a box).
    const Vec3d g(mSettings.gravity);
    const double share = mPressure->addedMassShare();
    const double step = double(dt);
    for (const auto& solid : mSolids) {
        if (!solid->body) continue;
        Body& b = *solid->body;
        const double m = b.rigid.mass();
        const double r = share * double(mSettings.restDensity) * b.rigid.massProperties().volume
                         * b.wetShare / m;
        b.liquidForce = (b.gatheredForce + b.withheldImpulse / step) / (1 + r);
        b.liquidTorque = (b.gatheredTorque + b.withheldAngularImpulse / step) / (1 + r);
        b.withheldImpulse = b.liquidForce * (r * step);
        b.withheldAngularImpulse = b.liquidTorque * (r * step);
        b.rigid.accelerate(b.liquidForce + g * m + b.externalForce,
                           b.liquidTorque + b.externalTorque, double(dt));
        b.gatheredForce = b.gatheredTorque = Vec3d(0.0);
        b.wetShare = 0;
    }
    resolveBodyContacts(dt);
    for (const auto& solid : mSolids) {
        if (solid->body) solid->body->rigid.drift(double(dt));
    }
}

Aabb GhostSolver::bodyBox(const Body& b, double margin) const
{
    const RigidTransform xf = b.rigid.placementAt(b.rigid.state().time);
    Aabb box;
    for (const Vec3d& p : b.contactPoints) box.expand(xf.toWorld(Vec3(p)));
    return box.padded(Real(margin));
}

void GhostSolver::resolveBodyContacts(Real dt)
{
    // Each pair of bodies both ways (the points of one against the other's level set), then
    // each body against every static and moving solid, where their boxes meet; swept until a
    // sweep finds no contact, at most CONTACT_SWEEPS times (a box resting on another: one
    // sweep left the lower one the upper's push until the next step, g dt of jitter; eight
    // leave 1e-4 m/s, tests/sph/test_rigid_contact.cc).
    constexpr int CONTACT_SWEEPS = 8;
    ContactSettings cs;
    cs.restSpeed = 3.0 * double(mSettings.gravity.length()) * double(dt);
    cs.maxPushOut = 0.1 * double(mSettings.spacing);
    for (int sweep = 0; sweep < CONTACT_SWEEPS; ++sweep) {
        int touching = 0;
        for (const bool bodies : {true, false}) {
            for (std::size_t e = 0; e < mSolids.size(); ++e) {
                if (mSolids[e]->body) touching += contactsOf(e, bodies, dt, cs);
            }
        }
        if (touching == 0) break;
    }
}

int GhostSolver::contactsOf(std::size_t e, bool bodies, Real dt, ContactSettings cs)
{
    // Body e against the other bodies after it (`bodies`) or against the solids.
    Body& b = *mSolids[e]->body;
    const double time = mRun.time + double(dt);
    const double reach =
        (b.rigid.state().velocity.length() + b.rigid.angularVelocity().length() * b.radius)
            * double(dt)
        + cs.maxPushOut + double(mSettings.spacing);
    int touching = 0;
    for (std::size_t j = 0; j < mSolids.size(); ++j) {
        Solid& other = *mSolids[j];
        if (j == e || bool(other.body) != bodies || (other.body && j < e)) continue;
        ContactObstacle o;
        o.shape = &other.shape;
        o.moving = other.moving && !other.body ? &other : nullptr;
        o.body = other.body ? &other.body->rigid : nullptr;
        o.time = time;
        const RigidTransform place = other.moving ? other.at(time) : RigidTransform();
        if (!bodyBox(b, reach).intersects(place.toWorld(other.shape.bounds()))) continue;
        const RigidBodyMaterial& mine = b.rigid.material();
        cs.restitution = mine.restitution;
        cs.friction = mine.friction;
        if (other.body) {
            const RigidBodyMaterial& theirs = other.body->rigid.material();
            cs.restitution = std::max(mine.restitution, theirs.restitution);
            cs.friction = 0.5 * (mine.friction + theirs.friction);
        }
        touching += resolveContact(b.rigid, b.contactPoints, o, double(dt), cs);
        if (!other.body) continue;
        ContactObstacle back = o;
        back.shape = &mSolids[e]->shape;
        back.body = &b.rigid;
        touching +=
            resolveContact(other.body->rigid, other.body->contactPoints, back, double(dt), cs);
    }
    return touching;
}

void GhostSolver::giveCollisionImpulses(const std::vector<Vec3>& impulse,
                                        const std::vector<std::uint32_t>& hit)
{
    // The liquid's momentum change m (v_after - v_before) at each projected particle, reversed,
    // on the body it hit; then its ghosts take its new velocity.
    const std::vector<int> slot = bodySlots();
    const std::size_t bodies = std::size_t(*std::max_element(slot.begin(), slot.end()) + 1);
    const std::vector<Vec3d> centre = bodyCentres(slot);
    const auto& x = mParticles.positions();
    const std::vector<Wrench> totals = parallel::reduceInOrder(
        0, impulse.size(), std::vector<Wrench>(bodies),
        [&](std::size_t i, std::vector<Wrench>& acc) {
        if (hit[i] == NO_BODY_HIT) return;
        const std::size_t b = std::size_t(slot[hit[i]]);
        const Vec3d J = -Vec3d(impulse[i]);
        acc[b].force += J;
        acc[b].torque += (Vec3d(x[i]) - centre[b]).cross(J);
        },
        addWrenches, 4096);
    bool any = false;
    for (std::size_t e = 0; e < mSolids.size(); ++e) {
        if (slot[e] < 0) continue;
        const Wrench& w = totals[std::size_t(slot[e])];
        if (w.force == Vec3d(0.0) && w.torque == Vec3d(0.0)) continue;
        mSolids[e]->body->rigid.accelerate(w.force, w.torque, 1.0); // impulses: N s, N m s
        any = true;
    }
    if (any) moveSolids(mRun.time);
}

Real GhostSolver::fastestBody() const
{
    double fastest = 0;
    for (const auto& solid : mSolids) {
        if (!solid->body) continue;
        const RigidBody& b = solid->body->rigid;
        fastest = std::max(fastest, b.state().velocity.length()
                                        + b.angularVelocity().length() * solid->body->radius);
    }
    return Real(fastest);
}

} // namespace ghost
} // namespace ghostfx
