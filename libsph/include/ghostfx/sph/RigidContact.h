/// @file   RigidContact.h
/// @brief  Level-set contact of a rigid body against a solid or another body: impulses at the
///         body's surface points that keep them out of the other's level set over the coming
///         step, with restitution and Coulomb friction.
/// @details The scheme is the impulse-based contact of rigid bodies given as level sets
///          (Guendelman, Bridson and Fedkiw 2003, "Nonconvex rigid bodies with stacking",
///          SIGGRAPH): the body is sampled by points on its surface (its ghost particles there);
///          a point whose position after the coming drift, moving at its velocity now, lies
///          inside the other's level set is in contact, with the other's outward normal there.
///          Its relative normal velocity is raised to a target by an impulse along the normal
///          (through both bodies' effective masses, RigidBody::inverseMassAlong):
///           - a point outside now may approach exactly to the surface over the step, so a
///             resting body's gravity each step is taken out and it stays without jitter;
///           - a point already inside approaches no further;
///           - a point hitting faster than `restSpeed` leaves at `restitution` times its
///             approach speed.
///          A tangential impulse of at most `friction` times the normal one opposes the
///          tangential velocity (static friction where that stops it). The contact is first
///          taken as a whole, one impulse at the mean of its points along their mean normal
///          and with the restitution (so a face landing flat bounces without spinning, where
///          point-by-point impulses spun a dropped box at 26 rad/s); then the points are swept
///          a few times one by one without restitution (sequential impulses) for what the
///          whole left. Last, an overlap is undone by moving the body out along the deepest
///          point's normal, at most `maxPushOut` a step: a correction of position, which gives
///          the body no speed.
#pragma once

#include <ghostfx/sph/RigidBody.h>
#include <ghostfx/sph/RigidMotion.h>

#include <vector>

namespace ghostfx {
namespace sph {

/// What a body touches: a solid's level set where it is at the end of the step, and how fast
/// its points move.
struct ContactObstacle
{
    const LevelSet* shape = nullptr;
    /// A static solid: null. A solid on a prescribed motion: its motion, evaluated at `time`
    /// (the step's end) for its placement and velocity.
    const MovingLevelSet* moving = nullptr;
    /// A dynamic body: it takes the reaction, placed where its state's velocities take it over
    /// the step.
    RigidBody* body = nullptr;
    double time = 0;
};

struct ContactSettings
{
    double restitution = 0.2; ///< of the two bodies' (the solver takes the larger)
    double friction = 0.5;    ///< Coulomb coefficient (the solver takes the two's mean)
    double restSpeed = 0;     ///< below this approach speed (m/s) a contact does not bounce
    double maxPushOut = 0;    ///< deepest overlap undone in one step (m)
    int sweeps = 4;           ///< passes over the points
};

/// Contact impulses for `body` (its surface `points`, in its frame) against `obstacle` over
/// the coming drift of dt (s). Returns how many points were in contact in the last sweep.
int resolveContact(RigidBody& body, const std::vector<Vec3d>& points,
                   const ContactObstacle& obstacle, double dt, const ContactSettings& settings);

} // namespace sph
} // namespace ghostfx
