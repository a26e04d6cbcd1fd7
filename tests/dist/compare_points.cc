/// @file   compare_points.cc
/// @brief  Compare two liquid points files (`ghostfx run` outputs) particle by particle: the
///         same ids, and positions within a tolerance. Used by the MPI run test (one process
///         against several).
/// @details Usage: compare_points A.vdb B.vdb RMS_TOLERANCE WORST_TOLERANCE (metres). Prints
///          the counts and the differences; exit code 0 when the ids are the same and both
///          differences are within their tolerances, 1 otherwise.
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

namespace {

std::map<std::int64_t, openvdb::Vec3d> readPoints(const std::string& path)
{
    openvdb::io::File file(path);
    file.open();
    const auto grid =
        openvdb::gridPtrCast<openvdb::points::PointDataGrid>(file.readGrid("particles"));
    file.close();
    std::map<std::int64_t, openvdb::Vec3d> out;
    if (!grid) return out;
    const openvdb::math::Transform& xform = grid->transform();
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
        openvdb::points::AttributeHandle<openvdb::Vec3f> P(leaf->constAttributeArray("P"));
        openvdb::points::AttributeHandle<std::int64_t> id(leaf->constAttributeArray("id"));
        for (auto index = leaf->beginIndexOn(); index; ++index) {
            const openvdb::Vec3d voxel = index.getCoord().asVec3d() + P.get(*index);
            out[id.get(*index)] = xform.indexToWorld(voxel);
        }
    }
    return out;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 5) {
        std::fprintf(stderr, "usage: compare_points A.vdb B.vdb RMS_TOLERANCE WORST_TOLERANCE\n");
        return 2;
    }
    openvdb::initialize();
    const auto a = readPoints(argv[1]), b = readPoints(argv[2]);
    const double rmsTolerance = std::atof(argv[3]), worstTolerance = std::atof(argv[4]);
    std::size_t missing = 0;
    double sum2 = 0, worst = 0;
    for (const auto& [id, x] : a) {
        const auto it = b.find(id);
        if (it == b.end()) {
            ++missing;
            continue;
        }
        const double d = (x - it->second).length();
        sum2 += d * d;
        worst = std::max(worst, d);
    }
    const double rms = a.empty() ? 0 : std::sqrt(sum2 / double(a.size()));
    std::printf("%s: %zu particles, %s: %zu particles, %zu ids of the first missing in the "
                "second; position difference rms %.3e m, worst %.3e m (tolerances %.3e, %.3e)\n",
                argv[1], a.size(), argv[2], b.size(), missing, rms, worst, rmsTolerance,
                worstTolerance);
    const bool ok = !a.empty() && a.size() == b.size() && missing == 0 && rms <= rmsTolerance
                    && worst <= worstTolerance;
    return ok ? 0 : 1;
}
