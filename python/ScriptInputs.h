/// @file   ScriptInputs.h
/// @brief  What a Python script adds to a simulation beside its scene (solids, emitters, gas
///         sources, solid velocities it sets), and how a checkpoint carries it, so that
///         Simulation.resume() continues such a run without the script adding them again.
/// @details The additions are scene entries (vdbio::SceneSolid, SceneEmitter, SceneGasSource)
///          that the module appends to its own copy of the scene: the simulation adds them as
///          it adds the scene's, the previews draw the solids, and a resumed simulation built
///          from the copy adds them again in the same order (the solvers then take their
///          restored particles and emitter credits). In a checkpoint they are two attachments
///          (vdbio::CheckpointAttachments): "script_inputs.json", the entries without their
///          shapes, and "script_shapes.vdb", the shapes as an OpenVDB stream, bit for bit.
#pragma once

#include <ghostfx/sph/RigidMotion.h>
#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/Scene.h>

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace ghostfx {
namespace python {

/// A solid's motion as set_solid_velocity() sets it: from `start` (its placement at `time`, s),
/// translating at `velocity` (m/s), without turning.
struct SolidVelocity
{
    double time = 0;
    sph::RigidTransform start;
    sph::Vec3d velocity{0};

    sph::RigidMotion motion() const;
};

/// The additions to a scene: the entries past the scene's own (solids with `dynamic` are rigid
/// bodies), and the solid velocities set (by solid index, scene solids first).
struct ScriptInputs
{
    std::vector<vdbio::SceneSolid> solids;
    std::vector<vdbio::SceneEmitter> emitters;
    std::vector<vdbio::SceneGasSource> gasSources;
    std::map<std::size_t, SolidVelocity> velocities;

    bool empty() const
    {
        return solids.empty() && emitters.empty() && gasSources.empty() && velocities.empty();
    }
};

/// The attachments that carry `inputs` (none when it is empty).
vdbio::CheckpointAttachments toAttachments(const ScriptInputs& inputs);
/// The inputs carried by a checkpoint's attachments (empty for a checkpoint without them);
/// IoError naming the checkpoint `path` for attachments that cannot be read back.
ScriptInputs fromAttachments(const vdbio::CheckpointAttachments& attachments,
                             const std::string& path);

} // namespace python
} // namespace ghostfx
