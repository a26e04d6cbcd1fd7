/// @file   WhitewaterFile.cc
/// @brief  Whitewater particles as a PointDataGrid and fog grids, written atomically.
/// @details The points follow PointsFile.cc (positions bucketed by a PointIndexGrid, "P" as an
///          uncompressed float offset, every attribute routed through the same index grid).
///          The fog is a serial trilinear splat whose contributions are sorted before they are
///          summed, so the grids do not depend on the particles' order (WhitewaterFile.h).
#include "FrameGridsDetail.h"
#include "PointGridBuild.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/FrameFiles.h>
#include <ghostfx/vdbio/WhitewaterFile.h>

#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace ghostfx {
namespace vdbio {

namespace {

using openvdb::points::PointDataGrid;

constexpr const char* WHERE = "whitewater output";
/// Class values run from 0 to this (spray, foam, bubble).
constexpr std::int32_t MAX_TYPE = 2;

bool isPositiveFinite(double x) { return std::isfinite(x) && x > 0.0; }

/// Throw ValueError for arrays of different lengths, a type outside 0..MAX_TYPE or a
/// non-finite position, naming the arrays, the particle and the value.
void checkPoints(const WhitewaterPoints& p)
{
    const std::size_t n = p.positions.size();
    if (p.velocities.size() != n || p.ids.size() != n || p.types.size() != n
        || p.ages.size() != n) {
        throw ValueError(msg(WHERE, ": arrays of different lengths: positions ", n, ", velocities ",
                             p.velocities.size(), ", ids ", p.ids.size(), ", types ",
                             p.types.size(), ", ages ", p.ages.size()));
    }
    for (std::size_t k = 0; k < n; ++k) {
        if (p.types[k] < 0 || p.types[k] > MAX_TYPE) {
            throw ValueError(msg(WHERE, ": type ", p.types[k], " of particle ", k, " (id ",
                                 p.ids[k], "): expected 0 spray, 1 foam or 2 bubble"));
        }
        if (!sph::isFinite(p.positions[k])) {
            throw ValueError(msg(WHERE, ": position ", p.positions[k], " of particle ", k, " (id ",
                                 p.ids[k], ") is not finite"));
        }
    }
}

std::vector<openvdb::Vec3s> toVec3s(const std::vector<sph::Vec3>& v)
{
    std::vector<openvdb::Vec3s> out(v.size());
    for (std::size_t k = 0; k < v.size(); ++k)
        out[k] = openvdb::Vec3s(float(v[k][0]), float(v[k][1]), float(v[k][2]));
    return out;
}

/// The PointDataGrid "whitewater" of checked points (WhitewaterFile.h lists the attributes).
openvdb::GridBase::Ptr makeWhitewaterPointsGrid(const WhitewaterPoints& p,
                                                const WhitewaterGridOptions& options)
{
    // Positions in double, so the world-to-voxel conversion adds no rounding of its own.
    std::vector<openvdb::Vec3d> positions(p.positions.size());
    for (std::size_t k = 0; k < positions.size(); ++k)
        positions[k] = openvdb::Vec3d(p.positions[k][0], p.positions[k][1], p.positions[k][2]);
    const double voxelSize =
        options.pointsVoxelSize > 0.0 ? options.pointsVoxelSize : autoPointsVoxelSize(p.positions);
    detail::PointGridBuild build = detail::buildPointGrid(positions, voxelSize);
    detail::addAttribute(build, "v", toVec3s(p.velocities));
    detail::addAttribute(build, "id", p.ids);
    detail::addAttribute(build, "type", p.types);
    detail::addAttribute(build, "age", p.ages);
    // One radius for all: a uniform array, one value per leaf.
    const PointDataGrid::Ptr grid = build.grid;
    openvdb::points::appendAttribute<float>(grid->tree(), "pscale", float(options.pscale));

    grid->setName("whitewater");
    grid->setCreator("ghostfx");
    grid->insertMeta("type_names", openvdb::StringMetadata("0=spray,1=foam,2=bubble"));
    grid->insertMeta("point_count", openvdb::Int64Metadata(std::int64_t(positions.size())));
    return grid;
}

/// One particle's share of one voxel's volume fraction.
struct Contribution
{
    openvdb::Coord ijk;
    double fraction = 0;

    bool operator<(const Contribution& o) const
    {
        return std::make_tuple(ijk.x(), ijk.y(), ijk.z(), fraction)
               < std::make_tuple(o.ijk.x(), o.ijk.y(), o.ijk.z(), o.fraction);
    }
};

/// The nonzero trilinear shares V_p w_x w_y w_z / dx^3 of the particles of class `type` (all
/// when type < 0), sorted by voxel and value.
std::vector<Contribution> splat(const WhitewaterPoints& p, int type, double dx, double pscale)
{
    const double invDx = 1.0 / dx;
    const double fraction = 4.0 / 3.0 * openvdb::math::pi<double>() * pscale * pscale * pscale
                            * (invDx * invDx * invDx);
    std::vector<Contribution> out;
    for (std::size_t k = 0; k < p.positions.size(); ++k) {
        if (type >= 0 && p.types[k] != type) continue;
        int i0[3];
        double w[3][2];
        for (int d = 0; d < 3; ++d) {
            const double u = double(p.positions[k][d]) * invDx;
            const double lower = std::floor(u);
            i0[d] = int(lower);
            w[d][1] = u - lower;
            w[d][0] = 1.0 - w[d][1];
        }
        for (int c = 0; c < 8; ++c) {
            const int a = c & 1, b = (c >> 1) & 1, e = (c >> 2) & 1;
            const double weight = w[0][a] * w[1][b] * w[2][e];
            if (weight > 0.0) {
                out.push_back({openvdb::Coord(i0[0] + a, i0[1] + b, i0[2] + e), fraction * weight});
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

/// The fog grid of checked points and arguments (makeWhitewaterFog): each voxel's run of
/// sorted shares summed in double, then clamped to a volume fraction.
openvdb::FloatGrid::Ptr makeFog(const WhitewaterPoints& points, int type, double voxelSize,
                                double pscale, const std::string& name)
{
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
    grid->setName(name);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    detail::setCommonGridMetadata(*grid);

    const std::vector<Contribution> shares = splat(points, type, voxelSize, pscale);
    openvdb::FloatGrid::Accessor acc = grid->getAccessor();
    for (std::size_t k = 0; k < shares.size();) {
        double sum = 0.0;
        std::size_t end = k;
        for (; end < shares.size() && shares[end].ijk == shares[k].ijk; ++end)
            sum += shares[end].fraction;
        acc.setValue(shares[k].ijk, float(std::min(sum, 1.0)));
        k = end;
    }
    return grid;
}

} // namespace

void WhitewaterGridOptions::validate() const
{
    if (!isPositiveFinite(pscale)) {
        throw ValueError(msg(WHERE, ": pscale = ", pscale, " m: expected > 0 (particle radius)"));
    }
    if (!(std::isfinite(pointsVoxelSize) && pointsVoxelSize >= 0.0)) {
        throw ValueError(msg(WHERE, ": pointsVoxelSize = ", pointsVoxelSize,
                             " m: expected > 0, or 0 for automatic"));
    }
    if (!(std::isfinite(fogVoxelSize) && fogVoxelSize >= 0.0)) {
        throw ValueError(msg(WHERE, ": fogVoxelSize = ", fogVoxelSize,
                             " m: expected > 0, or 0 for no fog grids"));
    }
}

openvdb::FloatGrid::Ptr makeWhitewaterFog(const WhitewaterPoints& points, int type,
                                          double voxelSize, double pscale, const std::string& name)
{
    if (!isPositiveFinite(voxelSize)) {
        throw ValueError(
            msg(WHERE, ": fog '", name, "': voxel size = ", voxelSize, " m: expected > 0"));
    }
    if (!isPositiveFinite(pscale)) {
        throw ValueError(msg(WHERE, ": fog '", name, "': pscale = ", pscale, " m: expected > 0"));
    }
    if (type > MAX_TYPE) {
        throw ValueError(msg(WHERE, ": fog '", name, "': type ", type,
                             ": expected 0 spray, 1 foam, 2 bubble, or < 0 for all"));
    }
    checkPoints(points);
    return makeFog(points, type, voxelSize, pscale, name);
}

openvdb::GridPtrVec makeWhitewaterGrids(const WhitewaterPoints& points,
                                        const WhitewaterGridOptions& options)
{
    options.validate();
    checkPoints(points);
    openvdb::GridPtrVec grids{makeWhitewaterPointsGrid(points, options)};
    if (options.fogVoxelSize > 0.0) {
        for (int type = 0; type <= MAX_TYPE; ++type) {
            grids.push_back(makeFog(points, type, options.fogVoxelSize, options.pscale,
                                    WHITEWATER_FOG_NAMES[type]));
        }
    }
    return grids;
}

void writeWhitewaterFile(const std::string& path, const openvdb::GridPtrVec& grids,
                         const openvdb::MetaMap& fileMetadata)
{
    detail::checkOutputFolder(path, WHERE);
    detail::writeVdbFile(path, WHERE, openvdb::GridCPtrVec(grids.begin(), grids.end()),
                         fileMetadata);
}

} // namespace vdbio
} // namespace ghostfx
