/// @file   SplitMerge.h
/// @brief  Particle splitting by a pattern, and merging by mass decentration with re-splitting,
///         for the liquid-gas phase transition ([RYY15] Sec. 4.1-4.2, Eqs. 19-20, Fig. 3).
/// @details Works on an sph::ParticleSet with two named scalar channels:
///            - "h"      smoothing radius of each particle (m): the kernel support radius, as in
///                       [RYY15] (Mueller et al. 2003 kernels); particles differ after splitting.
///            - "splits" how many times the particle's line was split since it was last merged.
///          `addSplitChannels` adds both if missing.
///
///          Splitting (Sec. 4.1, Fig. 2): the mother is removed and its daughters appended with
///          new ids; daughter k sits at x + epsilon h o_k with mass lambda_k m, smoothing radius
///          alpha h and the mother's velocity and every other channel (temperature, ...). Mass and
///          momentum are conserved to one rounding of the largest daughter's mass (the residual of
///          the Real-precision masses is put on it); the centre of mass moves only by round-off
///          because sum_k lambda_k o_k = 0 for the symmetric patterns.
///
///          Merging (Sec. 4.2, Fig. 3). Choices where the paper leaves room, with reasons:
///          - Candidates: liquid particles (`candidateKind`) whose "splits" count reached
///            `splitThreshold` ("we split liquid particles only up to a threshold number of
///            splits"). The paper gives no value; the default is 3.
///          - Neighbourhood of a candidate M: "adjacent similar liquid particles" within M's
///            smoothing radius (Eq. 19). "Similar" is read as: same kind and smoothing radius
///            within a factor `maxSizeRatio` of h_M (merging very different sizes would smear the
///            fine ones). At most `maxMerged` nearest members are taken (M included); by default
///            as many as the re-split pattern has daughters, so a merge-resplit keeps the particle
///            count: merging the whole support (tens of particles) into one and re-splitting it
///            into 12 would coarsen the liquid, which Fig. 3 does not show. Only full groups are
///            merged by default: the raw eta scales with (mass length^2)^3, so comparing groups of
///            different sizes would favour small ones.
///          - Choice: Eq. 19 inertia of the group about x_M, Eq. 20 decentration
///            eta = |(tr I / 3)^3 - det I|; candidates are merged in increasing eta (ties by id),
///            greedily, skipping a candidate whose group overlaps one already merged in this call
///            (so eta always describes exactly the group that is merged). The paper merges "the
///            particle with the smallest mass decentration"; doing so repeatedly over disjoint
///            groups is the same rule applied to the whole set in one pass.
///          - The merged particle M' has the group's mass and momentum (velocity = momentum / mass,
///            so both are conserved). Position: the group's centre of mass by default, which also
///            conserves the first mass moment; the paper places M' "at the same position as M"
///            (MergePlacement::Candidate). Named channels (temperature, ...) and density/pressure
///            become mass-weighted means (conserving sum m T). Smoothing radius: volume sum
///            h' = (sum h_j^3)^(1/3) (a particle's volume m / rho scales with h^3 at a fixed
///            neighbour count), or from the mass at a reference density,
///            h' = hRef (m' / mRef)^(1/3) (MergeSizeRule::ReferenceDensity).
///          - Re-split (Fig. 3c): M' is split at once by `resplitPattern`; its daughters start with
///            "splits" = 0. The default pattern is an icosahedron without centre (equal masses, as
///            [RYY15] Sec. 4.2 notes of centre-free patterns) with alpha = 12^(-1/3), so the
///            daughters' h^3 add up to h'^3 (volume kept), and the epsilon minimising Eq. 18 at that
///            alpha (about 0.41).
///
///          All neighbour searches happen before the set changes; the neighbour grid must have been
///          built on the set's current positions and is stale afterwards.
#pragma once

#include "ghostfx/gas/SplitPatterns.h"

#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/ParticleSet.h>

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

namespace ghostfx {
namespace gas {

using sph::Index;
using sph::ParticleKind;
using sph::ParticleSet;
using sph::Vec3;

/// Name of the per-particle smoothing radius channel (m).
inline constexpr const char* SMOOTHING_RADIUS_CHANNEL = "h";
/// Name of the per-particle split counter channel (splits since the last merge).
inline constexpr const char* SPLIT_COUNT_CHANNEL = "splits";

/// Add the "h" channel filled with `smoothingRadius` (m, > 0) and the "splits" channel filled
/// with 0, each only if missing (existing values are kept). Returns the "h" channel.
std::vector<Real>& addSplitChannels(ParticleSet& particles, Real smoothingRadius);

/// What the daughters of a split become.
struct SplitOptions
{
    /// Kind of the outer daughters (e.g. Gas for evaporation and boiling); empty: the mother's.
    std::optional<ParticleKind> outerKind;
    /// Kind of the centre daughter (evaporation: it stays liquid); empty: the mother's.
    std::optional<ParticleKind> centreKind;
    /// Count this split in the daughters' "splits" channel (mother's count + 1).
    bool countSplit = true;
};

/// Split every particle in `which` (distinct indices) by `pattern` ([RYY15] Sec. 4.1). The
/// mothers are removed; their daughters are appended in the order of `which`, each mother's
/// daughters contiguous and in pattern order.
/// @return index of the first daughter (after the removal): the daughters of which[k] are
///         [first + k c, first + (k + 1) c) with c = pattern.childCount()
/// Throws ValueError if the "h" channel is missing, an index is out of range or repeated, or a
/// mother's h is not finite and > 0.
Index splitParticles(ParticleSet& particles, const std::vector<Index>& which,
                     const SplitPattern& pattern, const SplitOptions& options = SplitOptions());

/// Split one particle; see splitParticles. @return index of its first daughter.
Index splitParticle(ParticleSet& particles, Index i, const SplitPattern& pattern,
                    const SplitOptions& options = SplitOptions());

/// Inertia matrix of [RYY15] Eq. 19 of the particles `group` about the point xM (kg m^2),
/// row-major 3 x 3, summed in double.
std::array<double, 9> inertiaMatrix(const ParticleSet& particles, const Vec3& xM,
                                    const std::vector<Index>& group);

/// Mass decentration of [RYY15] Eq. 20: |(trace(I) / 3)^3 - det(I)| (kg^3 m^6). Zero for an
/// isotropic (sphere-like) mass distribution.
double massDecentration(const std::array<double, 9>& inertia);

/// How the merged particle M' is placed.
enum class MergePlacement {
    CentreOfMass, ///< group's centre of mass: conserves the first mass moment (default)
    Candidate,    ///< at the candidate M, as [RYY15] Sec. 4.2 says ("the same position as M")
};

/// How the merged particle's smoothing radius is set.
enum class MergeSizeRule {
    VolumeSum,        ///< h' = (sum_j h_j^3)^(1/3)
    ReferenceDensity, ///< h' = referenceRadius (m' / referenceMass)^(1/3)
};

/// Settings of mergeParticles, with documented defaults ([RYY15] gives no numbers for these).
struct MergeSettings
{
    int splitThreshold = 3; ///< "splits" count that makes a particle a candidate (>= 1)
    Real neighbourhoodFactor =
        Real(1);                 ///< neighbourhood radius / h_M (Eq. 19: the smoothing radius)
    Real maxSizeRatio = Real(2); ///< "similar": h_j / h_M in [1 / ratio, ratio] (>= 1)
    std::size_t maxMerged = 0;   ///< most particles in a group, M included; 0: daughters of
                                 ///< the re-split pattern (count-neutral merge-resplit)
    std::size_t minMerged = 0;   ///< fewest particles in a group, M included; 0: the
                                 ///< group limit (only full groups: equal-size groups keep
                                 ///< the raw eta of Eq. 20 comparable, and the count neutral)
    /// Only particles of this kind are candidates ([RYY15] merges liquid particles); empty: any.
    std::optional<ParticleKind> candidateKind = ParticleKind::Liquid;
    std::size_t maxMergesPerCall = 0; ///< 0: no limit
    MergePlacement placement = MergePlacement::CentreOfMass;
    MergeSizeRule sizeRule = MergeSizeRule::VolumeSum;
    Real referenceMass = Real(0);               ///< mRef (kg), for ReferenceDensity (> 0 there)
    Real referenceRadius = Real(0);             ///< hRef (m), for ReferenceDensity (> 0 there)
    bool resplit = true;                        ///< re-split M' at once (Fig. 3c)
    std::optional<SplitPattern> resplitPattern; ///< empty: defaultResplitPattern()

    /// Throws ValueError naming the field and the bad value.
    void validate() const;
    /// The re-split pattern in use (resplitPattern or the default).
    const SplitPattern& pattern() const;
    /// maxMerged with 0 resolved to the re-split pattern's daughter count (12 without resplit).
    std::size_t groupLimit() const;
    /// minMerged with 0 resolved to groupLimit().
    std::size_t groupMinimum() const;
};

/// Icosahedron without centre, alpha = 12^(-1/3), epsilon minimising Eq. 18 (computed once).
const SplitPattern& defaultResplitPattern();

/// One planned merge: candidate M, the group merged (M first, then by distance and id) and its
/// Eq. 20 decentration.
struct MergeGroup
{
    Index candidate = sph::INVALID_INDEX;
    std::vector<Index> members;
    double eta = 0;
};

/// Choose the merges of one pass (no change to the set): candidates in increasing eta, disjoint
/// groups. `grid` must be built on `particles.positions()` as they are now.
std::vector<MergeGroup> planMerges(const ParticleSet& particles, const sph::NeighborGrid& grid,
                                   const MergeSettings& settings);

/// Counts of one merge pass.
struct MergeResult
{
    std::size_t merges = 0;  ///< groups merged
    std::size_t removed = 0; ///< particles removed (the groups' members)
    std::size_t added = 0;   ///< particles added (M', or its daughters when re-splitting)
};

/// Apply planned merges: remove each group, append M' (or its re-split daughters).
MergeResult applyMerges(ParticleSet& particles, const std::vector<MergeGroup>& plan,
                        const MergeSettings& settings);

/// planMerges then applyMerges: one merge pass per solver step ([RYY15] Sec. 4.2, Fig. 3).
/// Requires the "h" channel; does nothing if there is no "splits" channel.
MergeResult mergeParticles(ParticleSet& particles, const sph::NeighborGrid& grid,
                           const MergeSettings& settings);

} // namespace gas
} // namespace ghostfx
