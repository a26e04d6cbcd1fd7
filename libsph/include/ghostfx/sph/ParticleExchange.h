/// @file   ParticleExchange.h
/// @brief  What a solver needs from the other processes of a simulation spread over several
///         (MPI ranks): ownership of a region, particle migration and halo copies, global
///         reductions. Implemented over MPI in libdist (dist::MpiExchange); a solver without
///         one runs alone, exactly as before.
/// @details A process owns the particles in its region and computes them. At the start of a
///          step, exchange() sends away the owned particles that left the region and brings
///          in halo copies: other processes' particles within a support radius of the region,
///          flagged with the HALO_CHANNEL scalar channel (1). The solver treats halo copies as
///          neighbours only (never as queries), refreshes their values from their owners after
///          each pass that changes them (refresh()), and agrees on anything global (the time
///          step, maxima, the blow-up check) through the reductions.
#pragma once

#include "ghostfx/sph/ParticleSet.h"

#include <string>
#include <vector>

namespace ghostfx {
namespace sph {

/// Scalar channel that marks halo copies (1) among a process's particles.
constexpr const char* HALO_CHANNEL = "halo";

class ParticleExchange
{
public:
    virtual ~ParticleExchange() = default;

    virtual int rank() const = 0;
    virtual int ranks() const = 0;

    /// Whether this process's region holds x (new particles are made only by their owner).
    virtual bool owns(const Vec3& x) const = 0;

    /// Drop the last step's halo copies, send the owned particles of `set` that left this
    /// region to their owners (receiving the ones that entered it), then append halo copies
    /// of the other processes' particles within `width` of this region.
    virtual void exchange(ParticleSet& set, Real width) = 0;

    /// Bring the halo copies' values of these channels up to date from their owners. Names:
    /// "velocity", "density", "pressure", "mass", or a scalar or vector channel of the set.
    virtual void refresh(ParticleSet& set, const std::vector<std::string>& channels) = 0;

    /// Remove the halo copies from `set`.
    virtual void dropHalo(ParticleSet& set) = 0;

    /// Every process's `mine`, on every process, in rank order (each process's in its own
    /// order). For small sets that every process must see whole (an emitter's surroundings).
    virtual std::vector<Vec3> allPositions(const std::vector<Vec3>& mine) = 0;

    virtual double maxOf(double value) = 0;
    virtual double minOf(double value) = 0;
    virtual double sumOf(double value) = 0;
};

} // namespace sph
} // namespace ghostfx
