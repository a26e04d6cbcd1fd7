/// @file   Checkpoint.h
/// @brief  HDF5 checkpoints of a simulation's solver states, so a run resumes bit for bit.
/// @details A checkpoint holds one sph::SolverState per solver of the simulation (one for a
///          liquid or a gas, three for a boiling liquid: the liquid, its vapour and the phase
///          transition), every particle channel in its native type and the solvers' scalars,
///          plus what a resume must check before trusting it: a schema version, the precision
///          of Real, and the effective scene settings as JSON text (STYLE.md rule 10:
///          "checkpoints carry a schema version and the settings, so a resume refuses a
///          mismatched cache"). Files are written atomically (writeAtomically).
///
///          Layout (schema 2), readable with h5dump / h5py:
///          - root attributes: `format` = "ghostfx checkpoint", `schema_version`, `real`
///            ("float" / "double"), `settings` (JSON), `frame`, `state_count`, and of the first
///            state `time` (s), `step`, `count_<kind>` for every particle kind (`count_liquid`,
///            `count_ghost_air`, ...);
///          - the first state at the root, every further state k in a group `/state_<k>`, each
///            laid out the same way:
///            - attributes `solver`, `particle_count`, `next_id`;
///            - `particles/position`, `particles/velocity` (N x 3 Real, m and m/s),
///              `particles/mass`, `particles/density`, `particles/pressure` (N Real, kg,
///              kg/m^3, Pa), `particles/kind` (N uint8, sph::ParticleKind), `particles/id`
///              (N int64);
///            - `particles/scalar/<name>` (N Real) and `particles/vector/<name>` (N x 3 Real)
///              for the named channels, each with a `default` attribute (the value new
///              particles get);
///            - `reals` and `integers`: groups whose attributes are the state's scalar maps
///              (double and int64).
///          - optionally a group `attachments`: named 1-D uint8 datasets, byte strings a
///            caller keeps beside the states (the Python module's added solids, emitters and
///            gas sources, CheckpointAttachments); a checkpoint without it has none.
///          Schema 1 is schema 2 with one state and no `state_count`: it is read as that, and a
///          liquid solver's state gets the keys that solver added since at the values its
///          schema-1 states were saved with (migrateSchema1 in Checkpoint.cc), so the solver
///          reads one set of keys.
#pragma once

#include <ghostfx/sph/SolverState.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// Version of the layout above; a reader takes it and every older one (1), and refuses newer.
constexpr int CHECKPOINT_SCHEMA_VERSION = 2;

/// The root attributes of a checkpoint, read without loading the particles.
struct CheckpointHeader
{
    int schemaVersion = 0;
    std::string solver;   ///< "ghost", "basic", ...
    std::string settings; ///< the effective scene settings (JSON text) of the run that wrote it
    int frame = 0;        ///< frames completed when it was written
    double time = 0;      ///< simulated time (s)
    std::int64_t step = 0;
    int stateCount = 0; ///< solver states in the file
    std::map<std::string, std::size_t> countPerKind; ///< kind name ("liquid", ...) -> count
};

/// Write `states` (at least one) to `path` (HDF5, atomically: a killed run keeps the previous
/// checkpoint). Parameters and errors as the one-state form below.
void writeCheckpoint(const std::string& path, const std::vector<sph::SolverState>& states,
                     const std::string& settingsJson, int frame);

/// Named byte strings stored beside the states (the group `attachments` of the layout above).
using CheckpointAttachments = std::map<std::string, std::string>;

/// The same, with `attachments` stored beside the states (none when empty).
void writeCheckpoint(const std::string& path, const std::vector<sph::SolverState>& states,
                     const std::string& settingsJson, int frame,
                     const CheckpointAttachments& attachments);

/// The attachments of a checkpoint (empty for one without); IoError naming the file and the
/// dataset for one that is not a 1-D uint8 dataset. No state or settings check is made here.
CheckpointAttachments readCheckpointAttachments(const std::string& path);

/// Write `state` to `path` (HDF5, atomically: a killed run keeps the previous checkpoint).
/// @param settingsJson  the effective scene settings as JSON text; a resume compares them
/// @param frame         frames completed (the frame the resumed run starts after)
/// Every Real channel is stored in the build's precision, so a read-back is bit-exact.
/// Throws IoError naming the file if it cannot be written.
void writeCheckpoint(const std::string& path, const sph::SolverState& state,
                     const std::string& settingsJson, int frame);

/// Read the root attributes only. Throws IoError naming the file if it is missing, not HDF5, or
/// not a ghostfx checkpoint. A schema version other than ours is reported, not refused (the
/// fields a different schema lacks keep their defaults; schema 1 has one state).
CheckpointHeader readCheckpointHeader(const std::string& path);

/// Read every solver state of a checkpoint back, in the order they were written. Refuses, with
/// one line naming the file:
///  - IoError: missing, unreadable, not HDF5 or not a ghostfx checkpoint, a malformed dataset;
///  - IoError: a schema version newer than CHECKPOINT_SCHEMA_VERSION
///    ("checkpoint 'x.h5': schema version 3, this ghostfx reads 1 to 2");
///  - IoError: written by a build whose Real has another precision (float vs double);
///  - SceneError: settings different from `expectedSettingsJson`, naming the first differing
///    key as a JSON pointer and both values ("checkpoint 'c.h5' was written with different
///    settings: /settings/stiffness is 2000 there, 5000 in this scene"). Numbers compare by
///    value (2000 equals 2000.0). An empty `expectedSettingsJson` skips this check (for tools
///    that inspect a checkpoint without a scene).
/// Throws ValueError if `expectedSettingsJson` is not valid JSON.
std::vector<sph::SolverState> readCheckpointStates(const std::string& path,
                                                   const std::string& expectedSettingsJson);

/// Read a checkpoint of one solver state back; refuses as readCheckpointStates does, and with
/// an IoError a file of several states.
sph::SolverState readCheckpoint(const std::string& path, const std::string& expectedSettingsJson);

/// The first difference between two JSON documents as "<pointer> is <a> there, <b> in this
/// scene" (or "... is missing there" / "is absent in this scene"), "" if they are equal.
/// Object keys are visited in sorted order. Exposed for the CLI and tests.
std::string firstSettingsDifference(const std::string& thereJson, const std::string& hereJson);

namespace detail {
/// Overwrite (or add) one root attribute of an existing file in place, as an int64 or a string.
/// Only for tests of the refusals above (a run never edits a checkpoint after writing it).
void patchCheckpointAttribute(const std::string& path, const std::string& name, std::int64_t value);
void patchCheckpointAttribute(const std::string& path, const std::string& name,
                              const std::string& value);
} // namespace detail

} // namespace vdbio
} // namespace ghostfx
