/// @file   PointsFile.cc
/// @brief  Particles as an OpenVDB PointDataGrid ("particles"), written atomically to a file of
///         its own.
/// @details OpenVDB points (Bailey et al., "OpenVDB Points", DigiPro 2016 course notes; API of
///          points/PointConversion.h): the selected positions are bucketed by a PointIndexGrid,
///          the PointDataGrid is created from it with "P" stored as a float offset from the voxel
///          centre (NullCodec: no quantisation), and every channel is appended and populated
///          through the same index grid so the attribute arrays follow the point order of "P".
///          Only this translation unit instantiates the points templates (STACK.md).
#include "FrameGridsDetail.h"
#include "PointGridBuild.h"
#include "RenderAttributes.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <openvdb/io/File.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace ghostfx {
namespace vdbio {

namespace {

using openvdb::points::PointDataGrid;
using openvdb::points::PointDataTree;
using openvdb::tools::PointIndexGrid;

/// Particle kinds known to this build, in value order (ParticleKind values are stored in files).
constexpr sph::ParticleKind ALL_KINDS[] = {sph::ParticleKind::Liquid, sph::ParticleKind::GhostAir,
                                           sph::ParticleKind::GhostSolid, sph::ParticleKind::Gas,
                                           sph::ParticleKind::Boundary};

const char* const BUILTIN_CHANNELS[] = {"v", "id", "density", "pressure", "mass", "kind"};

/// Values of the selected particles: out[k] = T(src[selection[k]]).
template <typename T, typename S>
std::vector<T> gatherSelected(const std::vector<S>& src, const std::vector<sph::Index>& selection)
{
    std::vector<T> out(selection.size());
    parallel::forEach(
        0, selection.size(), [&](std::size_t k) { out[k] = T(src[selection[k]]); }, 4096);
    return out;
}

std::vector<openvdb::Vec3s> gatherSelected3(const std::vector<sph::Vec3>& src,
                                            const std::vector<sph::Index>& selection)
{
    std::vector<openvdb::Vec3s> out(selection.size());
    parallel::forEach(
        0, selection.size(),
        [&](std::size_t k) {
        const sph::Vec3& a = src[selection[k]];
        out[k] = openvdb::Vec3s(float(a[0]), float(a[1]), float(a[2]));
        },
        4096);
    return out;
}

std::string kindNamesList()
{
    std::string out;
    for (sph::ParticleKind k : ALL_KINDS) {
        out += (out.empty() ? "" : ",") + std::to_string(unsigned(k)) + "=" + sph::kindName(k);
    }
    return out;
}

/// Append channel `name` (checked by checkPointsOutput) of the selected particles: a built-in,
/// a named channel of the set, else a render attribute.
void addChannel(detail::PointGridBuild& build,
                const sph::ParticleSet& particles, const std::vector<sph::Index>& selection,
                const PointsOptions& options, const std::string& name)
{
    if (name == "v") {
        detail::addAttribute(build, name, gatherSelected3(particles.velocities(), selection));
    } else if (name == "id") {
        detail::addAttribute(build, name,
                     gatherSelected<std::int64_t>(particles.ids(), selection));
    } else if (name == "density") {
        detail::addAttribute(build, name, gatherSelected<float>(particles.densities(), selection));
    } else if (name == "pressure") {
        detail::addAttribute(build, name, gatherSelected<float>(particles.pressures(), selection));
    } else if (name == "mass") {
        detail::addAttribute(build, name, gatherSelected<float>(particles.masses(), selection));
    } else if (name == "kind") {
        std::vector<std::int32_t> kinds(selection.size());
        for (std::size_t k = 0; k < selection.size(); ++k) {
            kinds[k] = std::int32_t(particles.kinds()[selection[k]]);
        }
        detail::addAttribute(build, name, kinds);
    } else if (particles.hasScalarChannel(name)) {
        detail::addAttribute(build, name,
                     gatherSelected<float>(particles.scalarChannel(name), selection));
    } else if (particles.hasVectorChannel(name)) {
        detail::addAttribute(build, name,
                     gatherSelected3(particles.vectorChannel(name), selection));
    } else {
        detail::addAttribute(build, name,
                     detail::renderAttribute(particles, selection, options, name));
    }
}

} // namespace

void PointsOptions::validate() const
{
    if (!(std::isfinite(voxelSize) && voxelSize >= 0.0)) {
        throw ValueError(
            msg("points output: voxel size = ", voxelSize, " m: expected > 0, or 0 for automatic"));
    }
    std::set<std::string> seen;
    for (const std::string& name : channels) {
        if (name.empty() || name == "P") {
            throw ValueError(msg("points output: channel '", name,
                                 "': expected a channel name other than P (always written)"));
        }
        if (!seen.insert(name).second) {
            throw ValueError(msg("points output: channel '", name, "' listed twice"));
        }
    }
}

double autoPointsVoxelSize(const std::vector<sph::Vec3>& positions)
{
    std::vector<openvdb::Vec3d> x(positions.size());
    for (std::size_t k = 0; k < x.size(); ++k)
        x[k] = openvdb::Vec3d(positions[k][0], positions[k][1], positions[k][2]);
    return double(
        openvdb::points::computeVoxelSize(openvdb::points::PointAttributeVector<openvdb::Vec3d>(x),
                                          PointsOptions::AUTO_POINTS_PER_VOXEL));
}

void checkPointsOutput(const sph::ParticleSet& particles, const PointsOptions& options,
                       const std::string& where)
{
    detail::validateFor(options, where, "points output");
    for (const std::string& name : options.channels) {
        bool builtin = false;
        for (const char* b : BUILTIN_CHANNELS) builtin = builtin || name == b;
        if (builtin || particles.hasScalarChannel(name) || particles.hasVectorChannel(name)
            || detail::checkRenderAttribute(particles, options, name, where)) {
            continue;
        }
        std::vector<std::string> available(std::begin(BUILTIN_CHANNELS),
                                           std::end(BUILTIN_CHANNELS));
        auto offer = [&](const std::string& n) {
            if (std::find(available.begin(), available.end(), n) == available.end())
                available.push_back(n);
        };
        for (const std::string& n : detail::renderAttributeNames(options)) offer(n);
        for (const std::string& n : particles.scalarChannelNames()) offer(n);
        for (const std::string& n : particles.vectorChannelNames()) offer(n);
        throw ValueError(msg(where, ": channel '", name,
                             "' not found: available: ", detail::joinNames(available)));
    }
}

detail::PointGridBuild detail::buildPointGrid(const std::vector<openvdb::Vec3d>& positions,
                                              double voxelSize)
{
    const openvdb::points::PointAttributeVector<openvdb::Vec3d> positionArray(positions);
    const openvdb::math::Transform::Ptr xform =
        openvdb::math::Transform::createLinearTransform(voxelSize);
    PointGridBuild build;
    build.index = openvdb::tools::createPointIndexGrid<PointIndexGrid>(positionArray, *xform);
    build.grid = openvdb::points::createPointDataGrid<openvdb::points::NullCodec, PointDataGrid>(
        *build.index, positionArray, *xform);
    return build;
}

openvdb::GridBase::Ptr makePointsGrid(const sph::ParticleSet& particles,
                                      const PointsOptions& options, const std::string& where)
{
    // Resolve every channel before any work, so a typo costs nothing.
    checkPointsOutput(particles, options, where);

    const std::vector<sph::Index> selection = detail::selectKinds(particles, options.kinds);

    // Positions in double, so the world-to-voxel conversion adds no rounding of its own.
    std::vector<openvdb::Vec3d> positions(selection.size());
    parallel::forEach(
        0, selection.size(),
        [&](std::size_t k) {
        const sph::Vec3& x = particles.positions()[selection[k]];
        positions[k] = openvdb::Vec3d(x[0], x[1], x[2]);
        },
        4096);
    double voxelSize = options.voxelSize;
    if (voxelSize == 0.0) {
        const openvdb::points::PointAttributeVector<openvdb::Vec3d> positionArray(positions);
        voxelSize = double(
            openvdb::points::computeVoxelSize(positionArray, PointsOptions::AUTO_POINTS_PER_VOXEL));
    }
    detail::PointGridBuild build = detail::buildPointGrid(positions, voxelSize);
    for (const std::string& name : options.channels)
        addChannel(build, particles, selection, options, name);

    PointDataGrid::Ptr grid = build.grid;
    grid->setName("particles");
    grid->setCreator("ghostfx");
    grid->insertMeta("kind_names", openvdb::StringMetadata(kindNamesList()));
    grid->insertMeta("point_count", openvdb::Int64Metadata(std::int64_t(selection.size())));
    std::string written;
    for (sph::ParticleKind k : options.kinds)
        written += (written.empty() ? "" : ",") + std::string(sph::kindName(k));
    grid->insertMeta("kinds_written", openvdb::StringMetadata(written));
    return grid;
}

openvdb::GridBase::Ptr mergePointsGrids(const std::vector<openvdb::GridBase::Ptr>& pieces)
{
    PointDataGrid::Ptr merged;
    std::int64_t count = 0;
    for (const openvdb::GridBase::Ptr& base : pieces) {
        PointDataGrid::Ptr piece = openvdb::gridPtrCast<PointDataGrid>(base);
        if (!piece) throw ValueError("points merge: a piece is not a PointDataGrid");
        if (!merged) {
            merged = piece;
        } else if (!(piece->transform() == merged->transform())) {
            throw ValueError("points merge: the pieces have different voxel sizes");
        } else {
            // Move the piece's leaves over: they must not overlap the merged ones.
            std::vector<openvdb::Coord> origins;
            for (auto leaf = piece->tree().cbeginLeaf(); leaf; ++leaf)
                origins.push_back(leaf->origin());
            for (const openvdb::Coord& origin : origins) {
                if (merged->tree().probeConstLeaf(origin)) {
                    throw ValueError(msg("points merge: two pieces hold the leaf at ", origin,
                                         " (the pieces must own disjoint leaves)"));
                }
                auto* leaf = piece->tree().template stealNode<PointDataTree::LeafNodeType>(
                    origin, openvdb::PointDataIndex32(0), false);
                merged->tree().addLeaf(leaf);
            }
        }
        if (auto c = piece->getMetadata<openvdb::Int64Metadata>("point_count")) count += c->value();
    }
    if (!merged) throw ValueError("points merge: no pieces");
    // One descriptor for every leaf (each piece made its own, with the same attributes).
    auto first = merged->tree().beginLeaf();
    if (first) {
        const auto descriptor = first->attributeSet().descriptorPtr();
        for (auto leaf = merged->tree().beginLeaf(); leaf; ++leaf) {
            if (!(leaf->attributeSet().descriptor() == *descriptor)) {
                throw ValueError("points merge: the pieces carry different attributes");
            }
            leaf->resetDescriptor(descriptor);
        }
    }
    merged->insertMeta("point_count", openvdb::Int64Metadata(count));
    return merged;
}

void writePointsGridFile(const std::string& path, const openvdb::GridBase::ConstPtr& grid,
                         const openvdb::MetaMap& fileMetadata)
{
    detail::checkOutputFolder(path, "points output");
    detail::writeVdbFile(path, "points output", openvdb::GridCPtrVec{grid}, fileMetadata);
}

void writePointsFile(const std::string& path, const sph::ParticleSet& particles,
                     const PointsOptions& options, const openvdb::MetaMap& fileMetadata)
{
    options.validate();
    detail::checkOutputFolder(path, "points output");
    writePointsGridFile(path, makePointsGrid(particles, options, msg("points output '", path, "'")),
                        fileMetadata);
}

} // namespace vdbio
} // namespace ghostfx
