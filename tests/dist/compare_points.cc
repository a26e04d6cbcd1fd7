/// @file   compare_points.cc
/// @brief  Compare two liquid points files (`ghostfx run` outputs). Used by the MPI run tests
///         (one process against several).
/// @details Usage:
///            compare_points A.vdb B.vdb RMS_TOLERANCE WORST_TOLERANCE
///          particle by particle: the same ids, positions within the tolerances (metres);
///            compare_points --cloud A.vdb B.vdb COUNT_TOLERANCE CENTRE_TOLERANCE FAR FAR_SHARE
///          as clouds, for liquid whose particles are not the same ones (an emitter samples
///          new liquid from its surroundings, which differ with the process count): particle
///          counts within COUNT_TOLERANCE (relative), centres of mass within CENTRE_TOLERANCE
///          (metres), and at most FAR_SHARE of either cloud's particles farther than FAR
///          (metres) from every particle of the other (the same body of liquid, not one with a
///          lost or extra splash). Prints the measures; exit code 0 when all hold, 1 otherwise.
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

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
            if (!out.emplace(id.get(*index), xform.indexToWorld(voxel)).second) {
                // Two particles with one id: a particle written twice, or ids not unique.
                std::printf("%s: id %lld appears twice\n", path.c_str(),
                            static_cast<long long>(id.get(*index)));
                std::exit(1);
            }
        }
    }
    return out;
}

/// Share of `from`'s points farther than `far` from every point of `to`.
double farShare(const std::vector<openvdb::Vec3d>& from, const std::vector<openvdb::Vec3d>& to,
                double far)
{
    if (from.empty()) return 0;
    const auto cellOf = [far](const openvdb::Vec3d& x) {
        return openvdb::Coord(int(std::floor(x[0] / far)), int(std::floor(x[1] / far)),
                              int(std::floor(x[2] / far)));
    };
    const auto key = [](const openvdb::Coord& c) {
        return (std::int64_t(c[0]) * 73856093) ^ (std::int64_t(c[1]) * 19349663)
               ^ (std::int64_t(c[2]) * 83492791);
    };
    std::unordered_multimap<std::int64_t, std::size_t> cells;
    for (std::size_t k = 0; k < to.size(); ++k) cells.emplace(key(cellOf(to[k])), k);
    std::size_t farCount = 0;
    for (const openvdb::Vec3d& x : from) {
        const openvdb::Coord c = cellOf(x);
        bool near = false;
        for (int dx = -1; dx <= 1 && !near; ++dx)
            for (int dy = -1; dy <= 1 && !near; ++dy)
                for (int dz = -1; dz <= 1 && !near; ++dz) {
                    const auto range = cells.equal_range(key(c.offsetBy(dx, dy, dz)));
                    for (auto it = range.first; it != range.second && !near; ++it)
                        near = (to[it->second] - x).length() <= far;
                }
        farCount += !near;
    }
    return double(farCount) / double(from.size());
}

int compareClouds(int argc, char** argv)
{
    if (argc != 8) {
        std::fprintf(stderr, "usage: compare_points --cloud A.vdb B.vdb COUNT_TOLERANCE "
                             "CENTRE_TOLERANCE FAR FAR_SHARE\n");
        return 2;
    }
    std::vector<openvdb::Vec3d> a, b;
    for (const auto& [id, x] : readPoints(argv[2])) a.push_back(x);
    for (const auto& [id, x] : readPoints(argv[3])) b.push_back(x);
    const double countTolerance = std::atof(argv[4]), centreTolerance = std::atof(argv[5]);
    const double far = std::atof(argv[6]), farTolerance = std::atof(argv[7]);
    const auto centre = [](const std::vector<openvdb::Vec3d>& p) {
        openvdb::Vec3d c(0);
        for (const auto& x : p) c += x;
        return p.empty() ? c : c / double(p.size());
    };
    const double count = a.empty() ? 1 : std::abs(double(b.size()) / double(a.size()) - 1);
    const openvdb::Vec3d ca = centre(a), cb = centre(b);
    const double shift = (cb - ca).length();
    const double farA = farShare(a, b, far), farB = farShare(b, a, far);
    std::printf("%s: %zu particles, %s: %zu particles (%.2f %% apart, tolerance %.2f %%); centres "
                "of mass (%.4f %.4f %.4f) and (%.4f %.4f %.4f) m, %.3e m apart (tolerance %.3e); "
                "farther than %.3e m from the other cloud: %.3f %% and %.3f %% (tolerance %.3f "
                "%%)\n",
                argv[2], a.size(), argv[3], b.size(), 100 * count, 100 * countTolerance, ca[0],
                ca[1], ca[2], cb[0], cb[1], cb[2], shift, centreTolerance, far, 100 * farA,
                100 * farB, 100 * farTolerance);
    const bool ok = !a.empty() && count <= countTolerance && shift <= centreTolerance
                    && farA <= farTolerance && farB <= farTolerance;
    return ok ? 0 : 1;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc > 1 && std::string(argv[1]) == "--cloud") {
        openvdb::initialize();
        return compareClouds(argc, argv);
    }
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
