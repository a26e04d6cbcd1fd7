/// @file   KeyedMotion.cc
/// @brief  Keyed rigid motion (KeyedMotion.h): interpolation, rates and the rotation matrices.
#include <ghostfx/sph/KeyedMotion.h>

#include <algorithm>
#include <cmath>

namespace ghostfx {
namespace sph {

RigidKey KeyedMotion::at(double time) const
{
    if (keys.empty()) return RigidKey{};
    if (time <= keys.front().time) return keys.front();
    if (time >= keys.back().time) return keys.back();
    const auto upper = std::upper_bound(keys.begin(), keys.end(), time,
                                        [](double t, const RigidKey& k) { return t < k.time; });
    const RigidKey& b = *upper;
    const RigidKey& a = *(upper - 1);
    const double s = (time - a.time) / (b.time - a.time);
    RigidKey k;
    k.time = time;
    k.translate = a.translate + (b.translate - a.translate) * s;
    k.rotateDegrees = a.rotateDegrees + (b.rotateDegrees - a.rotateDegrees) * s;
    return k;
}

RigidKey KeyedMotion::rate(double time) const
{
    RigidKey r;
    r.time = time;
    if (keys.size() < 2 || time < keys.front().time || time >= keys.back().time) return r;
    const auto upper = std::upper_bound(keys.begin(), keys.end(), time,
                                        [](double t, const RigidKey& k) { return t < k.time; });
    const RigidKey& b = *upper;
    const RigidKey& a = *(upper - 1);
    const double span = b.time - a.time;
    r.translate = (b.translate - a.translate) / span;
    r.rotateDegrees = (b.rotateDegrees - a.rotateDegrees) / span;
    return r;
}

namespace {

/// The three factors of R = Rz Ry Rx for angles in degrees, and each one's derivative with
/// respect to its own angle (radians).
struct AxisRotations
{
    openvdb::math::Mat3d rx, ry, rz, drx, dry, drz;

    explicit AxisRotations(const Vec3d& degrees)
    {
        const double d2r = M_PI / 180.0;
        const double cx = std::cos(degrees[0] * d2r), sx = std::sin(degrees[0] * d2r);
        const double cy = std::cos(degrees[1] * d2r), sy = std::sin(degrees[1] * d2r);
        const double cz = std::cos(degrees[2] * d2r), sz = std::sin(degrees[2] * d2r);
        const double one = 1, zero = 0;
        rx = openvdb::math::Mat3d(one, zero, zero, zero, cx, -sx, zero, sx, cx);
        ry = openvdb::math::Mat3d(cy, zero, sy, zero, one, zero, -sy, zero, cy);
        rz = openvdb::math::Mat3d(cz, -sz, zero, sz, cz, zero, zero, zero, one);
        drx = openvdb::math::Mat3d(zero, zero, zero, zero, -sx, -cx, zero, cx, -sx);
        dry = openvdb::math::Mat3d(-sy, zero, cy, zero, zero, zero, -cy, zero, -sy);
        drz = openvdb::math::Mat3d(-sz, -cz, zero, cz, -sz, zero, zero, zero, zero);
    }
};

} // namespace

openvdb::math::Mat3d KeyedMotion::rotationRate(const Vec3d& degrees, const Vec3d& degreesPerSecond)
{
    // dR/dt = Rz' Ry Rx wz + Rz Ry' Rx wy + Rz Ry Rx' wx.
    const AxisRotations a(degrees);
    const Vec3d w = degreesPerSecond * (M_PI / 180.0);
    return a.drz * a.ry * a.rx * w[2] + a.rz * a.dry * a.rx * w[1] + a.rz * a.ry * a.drx * w[0];
}

openvdb::math::Mat3d KeyedMotion::rotation(const Vec3d& degrees)
{
    const AxisRotations a(degrees);
    return a.rz * a.ry * a.rx;
}

RigidMotion KeyedMotion::motion() const
{
    return [keyed = *this](double t) {
        const RigidKey k = keyed.at(t);
        const openvdb::math::Mat3d r = rotation(k.rotateDegrees);
        RigidTransform xf;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) xf.rotation(i, j) = Real(r(i, j));
        }
        xf.translation = Vec3(k.translate);
        const RigidKey rate = keyed.rate(t);
        const openvdb::math::Mat3d dr = rotationRate(k.rotateDegrees, rate.rotateDegrees);
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) xf.rotationRate(i, j) = Real(dr(i, j));
        }
        xf.translationRate = Vec3(rate.translate);
        xf.hasRates = true;
        return xf;
    };
}

} // namespace sph
} // namespace ghostfx
