/// @file   StudyMetrics.cc
/// @brief  The study's error metrics: density deviation, volume and mass drift, hydrostatic
///         pressure, free fall, the zero-gravity cube, the dam-break surge front, the plume top
///         and plane Poiseuille flow.
#include "StudyMetrics.h"

#include <ghostfx/sph/Exceptions.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>

namespace ghostfx {
namespace cmd {

using sph::ParticleKind;
using sph::Vec3;
using Json = nlohmann::json;

namespace {

/// Indices of the medium's own particles (liquid, or visible gas), no ghosts.
std::vector<std::size_t> members(const OutputMedium& m)
{
    std::vector<std::size_t> out;
    const sph::ParticleSet& p = *m.particles;
    out.reserve(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (std::find(m.kinds.begin(), m.kinds.end(), p.kinds()[i]) != m.kinds.end())
            out.push_back(i);
    }
    return out;
}

/// The q-th percentile (0..100) of `values` (nearest rank); NaN if empty.
double percentile(std::vector<double> values, double q)
{
    if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t k = std::min(
        values.size() - 1, std::size_t(std::floor(q / 100.0 * double(values.size() - 1) + 0.5)));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
    return values[k];
}

/// Reads a metric's options: every key must be asked for, values are checked.
class Options
{
public:
    Options(const Json& json, std::string where) : mJson(json), mWhere(std::move(where)) {}

    Vec3 direction(const std::string& key, const Vec3& fallback)
    {
        mKnown.insert(key);
        if (!mJson.contains(key)) return fallback;
        const Json& v = mJson[key];
        if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number()
            || !v[2].is_number()) {
            fail(key, v, "expected [x, y, z]");
        }
        const Vec3 d(sph::Real(v[0].get<double>()), sph::Real(v[1].get<double>()),
                     sph::Real(v[2].get<double>()));
        if (!(d.length() > 0)) fail(key, v, "expected a non-zero direction");
        return d / d.length();
    }

    std::string choice(const std::string& key, const std::string& fallback,
                       const std::vector<std::string>& choices)
    {
        mKnown.insert(key);
        if (!mJson.contains(key)) return fallback;
        const Json& v = mJson[key];
        std::string list;
        for (const std::string& c : choices) {
            if (v.is_string() && v.get<std::string>() == c) return c;
            list += (list.empty() ? "\"" : ", \"") + c + "\"";
        }
        fail(key, v, "expected one of " + list);
    }

    double number(const std::string& key, double fallback, double lo, double hi)
    {
        mKnown.insert(key);
        if (!mJson.contains(key)) return fallback;
        const Json& v = mJson[key];
        if (!v.is_number() || v.get<double>() < lo || v.get<double>() > hi) {
            fail(key, v, msg("expected a number in [", lo, ", ", hi, "]"));
        }
        return v.get<double>();
    }

    void finish() const
    {
        for (auto it = mJson.begin(); it != mJson.end(); ++it) {
            if (it.key() != "metric" && !mKnown.count(it.key())) {
                throw SceneError(msg(mWhere, ".", it.key(),
                                     ": unknown option of this metric (options: ", known(), ")"));
            }
        }
    }

private:
    [[noreturn]] void fail(const std::string& key, const Json& v, const std::string& what) const
    {
        throw SceneError(msg(mWhere, ".", key, " = ", v.dump(), ": ", what));
    }
    std::string known() const
    {
        std::string s;
        for (const std::string& k : mKnown) s += (s.empty() ? "" : ", ") + k;
        return s.empty() ? "none" : s;
    }

    const Json& mJson;
    std::string mWhere;
    std::set<std::string> mKnown;
};

// density_error -----------------------------------------------------------------------------------
// |rho_i / rho0 - 1| over the medium's particles after every frame: the mean over particles,
// averaged over frames, and the largest value seen. The reference is rho0 itself: a weakly
// compressible SPH liquid is meant to stay at its rest density.

class DensityError : public Metric
{
public:
    explicit DensityError(std::string medium) : Metric("density_error", std::move(medium)) {}

    void frame(const MetricSample& s) override
    {
        const sph::ParticleSet& p = *s.medium->particles;
        double sum = 0;
        std::size_t n = 0;
        for (std::size_t i : members(*s.medium)) {
            const double e = std::abs(double(p.densities()[i]) / s.medium->restDensity - 1.0);
            sum += e;
            mMax = std::max(mMax, e);
            ++n;
        }
        if (n == 0) return;
        mMeanSum += sum / double(n);
        ++mFrames;
    }

    std::vector<std::pair<std::string, double>> values() const override
    {
        return {{"density_error_mean", mFrames ? mMeanSum / double(mFrames) : NAN},
                {"density_error_max", mMax}};
    }

private:
    double mMeanSum = 0, mMax = 0;
    int mFrames = 0;
};

// volume_drift ------------------------------------------------------------------------------------
// The volume the particles represent, V = sum m_i / rho_i, against the volume they were sampled
// to fill, V0 = sum m_i / rho0 (every particle was given m = rho0 x its share of the sampled
// volume); and the mass M = sum m_i against its value after the first frame. Both as the
// largest relative deviation seen over the run.

class VolumeDrift : public Metric
{
public:
    explicit VolumeDrift(std::string medium) : Metric("volume_drift", std::move(medium)) {}

    void frame(const MetricSample& s) override
    {
        const sph::ParticleSet& p = *s.medium->particles;
        double volume = 0, sampled = 0, mass = 0;
        for (std::size_t i : members(*s.medium)) {
            const double m = p.masses()[i];
            mass += m;
            sampled += m / s.medium->restDensity;
            volume += m / double(p.densities()[i]);
        }
        if (sampled > 0) mVolume = std::max(mVolume, std::abs(volume / sampled - 1.0));
        if (mMass0 < 0) mMass0 = mass;
        else if (mMass0 > 0) mMassDrift = std::max(mMassDrift, std::abs(mass / mMass0 - 1.0));
    }

    std::vector<std::pair<std::string, double>> values() const override
    {
        return {{"volume_error", mVolume}, {"mass_drift", mMassDrift}};
    }

private:
    double mVolume = 0, mMass0 = -1, mMassDrift = 0;
};

// hydrostatic_pressure ----------------------------------------------------------------------------
// A liquid at rest under gravity g has p = rho0 |g| d at depth d below its free surface. Over the
// second half of the run (the tank has settled) the liquid is cut into layers one spacing thick
// by depth; each layer's mean pressure and mean depth are accumulated over those frames. The
// error is the rms over layers (weighted by their particle counts) of p_layer - rho0 |g| d_layer,
// divided by the bottom pressure rho0 |g| H: the systematic error of the pressure profile. The
// surface is the top particle's height plus half a spacing (a particle stands for the cube
// around it), H the depth from there to half a spacing below the lowest particle.
// The balance error compares instead with |g| times the integral of the measured density from
// the surface down: the exact equilibrium of the liquid as compressed as it is, so it isolates
// the force balance from the compressibility that a finite stiffness allows.
// Also reported: the particles' own rms deviation on the same scale (the profile error plus the
// pressure noise of a weakly compressible liquid, which grows with the stiffness), and the
// least-squares slope of p against d, relative to rho0 |g| (0 is exact).

class HydrostaticPressure : public Metric
{
public:
    explicit HydrostaticPressure(double fromFraction)
        : Metric("hydrostatic_pressure")
        , mFrom(fromFraction)
    {}

    void start(const MetricSample& s) override
    {
        if (!(s.medium->gravity.length() > 0)) {
            throw SceneError("metric hydrostatic_pressure: the liquid has no gravity "
                             "(settings.gravity = [0, 0, 0])");
        }
    }

    void frame(const MetricSample& s) override
    {
        if (double(s.frame) < mFrom * double(s.lastFrame)) return;
        const OutputMedium& m = *s.medium;
        const sph::ParticleSet& p = *m.particles;
        const double g = m.gravity.length();
        const Vec3 up = -m.gravity / sph::Real(g);
        const std::vector<std::size_t> liquid = members(m);
        if (liquid.empty()) return;
        double top = -std::numeric_limits<double>::max(),
               bottom = std::numeric_limits<double>::max();
        for (std::size_t i : liquid) {
            const double h = p.positions()[i].dot(up);
            top = std::max(top, h);
            bottom = std::min(bottom, h);
        }
        top += 0.5 * m.spacing;
        const double depth = top - bottom + 0.5 * m.spacing;
        mScale = m.restDensity * g;
        mRestDensity = m.restDensity;
        mSpacing = m.spacing;
        mDepthSum += depth;
        double sq = 0, sdd = 0, sdp = 0, sd = 0, sp = 0;
        for (std::size_t i : liquid) {
            const double d = top - p.positions()[i].dot(up);
            const double pi = p.pressures()[i];
            sq += (pi - mScale * d) * (pi - mScale * d);
            sd += d;
            sp += pi;
            sdd += d * d;
            sdp += d * pi;
            Layer& layer = mLayers[int(std::floor(d / m.spacing))];
            layer.depth += d;
            layer.pressure += pi;
            layer.density += p.densities()[i];
            ++layer.count;
        }
        const double n = double(liquid.size());
        mNoiseSum += std::sqrt(sq / n) / (mScale * depth);
        const double denominator = n * sdd - sd * sd;
        if (denominator > 0) mSlopeSum += (n * sdp - sd * sp) / denominator / mScale - 1.0;
        ++mFrames;
    }

    std::vector<std::pair<std::string, double>> values() const override
    {
        // The balance reference integrates the measured layer densities from the surface down:
        // p_bal(d) = |g| (sum of rho_j h over the layers above + rho_k (d - k h)).
        const double g = mScale / mRestDensity;
        double sq = 0, sqBalance = 0, count = 0, above = 0;
        int next = 0;
        for (const auto& [index, layer] : mLayers) {
            const double d = layer.depth / layer.count, pl = layer.pressure / layer.count;
            const double rho = layer.density / layer.count;
            for (; next < index; ++next)
                above += rho * mSpacing; // layers with no particle: this density
            const double balance = g * (above + rho * (d - index * mSpacing));
            above += rho * mSpacing;
            next = index + 1;
            sq += layer.count * (pl - mScale * d) * (pl - mScale * d);
            sqBalance += layer.count * (pl - balance) * (pl - balance);
            count += layer.count;
        }
        const double depth = mFrames ? mDepthSum / mFrames : NAN;
        const double bottom = mScale * depth;
        return {
            {"hydrostatic_pressure_error", count > 0 ? std::sqrt(sq / count) / bottom : NAN},
            {"hydrostatic_balance_error", count > 0 ? std::sqrt(sqBalance / count) / bottom : NAN},
            {"hydrostatic_pressure_noise", mFrames ? mNoiseSum / mFrames : NAN},
            {"hydrostatic_slope_error", mFrames ? mSlopeSum / mFrames : NAN}};
    }

private:
    struct Layer
    {
        double depth = 0, pressure = 0, density = 0, count = 0;
    };
    double mFrom;
    std::map<int, Layer> mLayers;
    double mScale = 1, mRestDensity = 1, mSpacing = 1, mDepthSum = 0, mNoiseSum = 0, mSlopeSum = 0;
    int mFrames = 0;
};

// free_fall ---------------------------------------------------------------------------------------
// A liquid body with no solid in reach falls as a whole: its centre of mass follows
// c(t) = c0 + v0 t + g t^2 / 2 exactly, whatever the pressure and viscosity forces do inside
// (they are pairwise and cancel). The error is |c(T) - c_exact(T)| at the end (m), also in
// particle spacings.

class FreeFall : public Metric
{
public:
    FreeFall() : Metric("free_fall") {}

    void start(const MetricSample& s) override
    {
        centre(s, mC0, mV0);
        mT0 = s.time;
    }

    void frame(const MetricSample& s) override
    {
        Vec3d v;
        centre(s, mC, v);
        const double t = s.time - mT0;
        const Vec3d g(s.medium->gravity[0], s.medium->gravity[1], s.medium->gravity[2]);
        const Vec3d exact = mC0 + mV0 * t + g * (0.5 * t * t);
        mError = (mC - exact).length();
        mSpacing = s.medium->spacing;
    }

    std::vector<std::pair<std::string, double>> values() const override
    {
        return {{"free_fall_com_error", mError},
                {"free_fall_com_error_spacings", mError / mSpacing}};
    }

private:
    using Vec3d = openvdb::math::Vec3<double>;
    static void centre(const MetricSample& s, Vec3d& c, Vec3d& v)
    {
        const sph::ParticleSet& p = *s.medium->particles;
        c = v = Vec3d(0);
        const std::vector<std::size_t> liquid = members(*s.medium);
        for (std::size_t i : liquid) {
            c += Vec3d(p.positions()[i][0], p.positions()[i][1], p.positions()[i][2]);
            v += Vec3d(p.velocities()[i][0], p.velocities()[i][1], p.velocities()[i][2]);
        }
        if (!liquid.empty()) {
            c /= double(liquid.size());
            v /= double(liquid.size());
        }
    }
    Vec3d mC0, mV0, mC;
    double mT0 = 0, mError = NAN, mSpacing = 1;
};

// cube_shape --------------------------------------------------------------------------------------
// [SB12] Fig. 4: a liquid cube at rest in zero gravity has nothing to move it (no surface
// tension is modelled), so the exact answer is that every particle stays where it is. The
// shape error is the rms displacement of the particles from their starting positions (matched
// by id), in particle spacings; also the relative change of the cube's extent (its bounding box,
// averaged over the three axes), negative when it shrinks.

class CubeShape : public Metric
{
public:
    CubeShape() : Metric("cube_shape") {}

    void start(const MetricSample& s) override
    {
        const sph::ParticleSet& p = *s.medium->particles;
        if (s.medium->gravity.length() > 0) {
            throw SceneError(
                "metric cube_shape: expects zero gravity (set settings.gravity = [0, 0, 0])");
        }
        for (std::size_t i : members(*s.medium)) mStart[p.ids()[i]] = p.positions()[i];
        mExtent0 = extent(s);
    }

    void frame(const MetricSample& s) override
    {
        const sph::ParticleSet& p = *s.medium->particles;
        double sq = 0;
        std::size_t n = 0;
        for (std::size_t i : members(*s.medium)) {
            auto it = mStart.find(p.ids()[i]);
            if (it == mStart.end()) continue;
            sq += double((p.positions()[i] - it->second).lengthSqr());
            ++n;
        }
        mError = n ? std::sqrt(sq / double(n)) / s.medium->spacing : NAN;
        mExtentChange = extent(s) / mExtent0 - 1.0;
    }

    std::vector<std::pair<std::string, double>> values() const override
    {
        return {{"cube_shape_error", mError}, {"cube_extent_change", mExtentChange}};
    }

private:
    static double extent(const MetricSample& s)
    {
        const sph::ParticleSet& p = *s.medium->particles;
        Vec3 lo(std::numeric_limits<sph::Real>::max()), hi(-std::numeric_limits<sph::Real>::max());
        for (std::size_t i : members(*s.medium)) {
            lo = openvdb::math::minComponent(lo, p.positions()[i]);
            hi = openvdb::math::maxComponent(hi, p.positions()[i]);
        }
        // A particle stands for the cube of one spacing around it.
        const Vec3 e = hi - lo + Vec3(sph::Real(s.medium->spacing));
        return (double(e[0]) + e[1] + e[2]) / 3.0;
    }
    std::unordered_map<sph::ParticleId, Vec3> mStart;
    double mExtent0 = 1, mError = NAN, mExtentChange = NAN;
};

// poiseuille --------------------------------------------------------------------------------------
// Plane Poiseuille flow: a liquid between no-slip plates at y = 0 and y = gap, driven along x by
// the scene's gravity (its x component g), has the steady profile u(y) = g y (gap - y) / (2 nu).
// Over the last part of the run (from `from` of it), the liquid within `x_window` of x = 0 and
// `z_window` of z = 0 is cut into layers one spacing thick; each layer's mean x-velocity at its
// mean height is compared with u there. The error is the largest difference over the profile's
// peak g gap^2 / (8 nu).

class Poiseuille : public Metric
{
public:
    Poiseuille(double gap, double from, double xWindow, double zWindow)
        : Metric("poiseuille")
        , mGap(gap)
        , mFrom(from)
        , mX(xWindow)
        , mZ(zWindow)
    {}

    void start(const MetricSample& s) override
    {
        if (!(s.medium->viscosity > 0) || s.medium->gravity[0] == 0) {
            throw SceneError("metric poiseuille: expects a viscous liquid (settings.viscosity > 0) "
                             "driven along x (settings.gravity[0] != 0)");
        }
        const std::size_t layers = std::size_t(std::lround(mGap / s.medium->spacing));
        mU.assign(layers, 0.0);
        mY.assign(layers, 0.0);
        mCount.assign(layers, 0.0);
    }

    void frame(const MetricSample& s) override
    {
        if (double(s.frame) < mFrom * double(s.lastFrame)) return;
        const sph::ParticleSet& p = *s.medium->particles;
        const double h = mGap / double(mU.size());
        for (std::size_t i : members(*s.medium)) {
            const Vec3& x = p.positions()[i];
            if (std::abs(x[0]) > mX || std::abs(x[2]) > mZ) continue;
            const std::size_t k =
                std::size_t(std::clamp(std::floor(double(x[1]) / h), 0.0, double(mU.size() - 1)));
            mU[k] += double(p.velocities()[i][0]);
            mY[k] += double(x[1]);
            mCount[k] += 1;
        }
        const double g = s.medium->gravity[0], nu = s.medium->viscosity;
        const double peak = std::abs(g) * mGap * mGap / (8 * nu);
        mError = 0;
        for (std::size_t k = 0; k < mU.size(); ++k) {
            if (mCount[k] == 0) continue;
            const double y = mY[k] / mCount[k];
            const double exact = g * y * (mGap - y) / (2 * nu);
            mError = std::max(mError, std::abs(mU[k] / mCount[k] - exact) / peak);
        }
    }

    std::vector<std::pair<std::string, double>> values() const override
    {
        return {{"poiseuille_error", mError}};
    }

private:
    double mGap, mFrom, mX, mZ;
    std::vector<double> mU, mY, mCount;
    double mError = NAN;
};

// surge_front and plume_rise ----------------------------------------------------------------------
// A position along a direction, taken as a high percentile over the medium's particles (so one
// stray droplet or puff does not set it), after every frame: the dam break's surge front along
// the floor, the plume's top along "up". The study compares the trace with a reference run.

class Front : public Metric
{
public:
    Front(std::string name, std::string medium, const Vec3& direction, double percentileRank)
        : Metric(std::move(name), std::move(medium))
        , mDirection(direction)
        , mRank(percentileRank)
    {}

    /// The trace starts with the initial state (NaN where the medium is still empty, as a gas
    /// before its source has emitted).
    void start(const MetricSample& s) override { mTrace = {measure(s)}; }
    void frame(const MetricSample& s) override { mTrace.push_back(measure(s)); }

    std::vector<std::pair<std::string, double>> values() const override
    {
        return {{name() + "_final", mTrace.empty() ? NAN : mTrace.back()}};
    }
    std::vector<double> trace() const override { return mTrace; }

private:
    double measure(const MetricSample& s) const
    {
        const sph::ParticleSet& p = *s.medium->particles;
        std::vector<double> along;
        for (std::size_t i : members(*s.medium)) along.push_back(p.positions()[i].dot(mDirection));
        return percentile(std::move(along), mRank);
    }
    Vec3 mDirection;
    double mRank;
    std::vector<double> mTrace;
};

} // namespace

const std::vector<std::string>& metricNames()
{
    static const std::vector<std::string> names = {
        "density_error", "volume_drift", "hydrostatic_pressure", "free_fall", "cube_shape",
        "surge_front",   "plume_rise",   "poiseuille"};
    return names;
}

std::string primaryErrorColumn(const std::string& metric, bool haveReference)
{
    static const std::map<std::string, std::string> primary = {
        {"density_error", "density_error_mean"},
        {"volume_drift", "volume_error"},
        {"hydrostatic_pressure", "hydrostatic_pressure_error"},
        {"free_fall", "free_fall_com_error"},
        {"cube_shape", "cube_shape_error"},
        {"poiseuille", "poiseuille_error"}};
    auto it = primary.find(metric);
    if (it != primary.end()) return it->second;
    return haveReference ? metric + "_error" : metric + "_final";
}

std::unique_ptr<Metric> makeMetric(const MetricSpec& spec, const std::string& where)
{
    Options o(spec.options, where);
    std::unique_ptr<Metric> metric;
    if (spec.name == "density_error" || spec.name == "volume_drift") {
        const std::string medium = o.choice("medium", "liquid", {"liquid", "gas"});
        if (spec.name == "density_error") metric = std::make_unique<DensityError>(medium);
        else metric = std::make_unique<VolumeDrift>(medium);
    } else if (spec.name == "hydrostatic_pressure") {
        metric = std::make_unique<HydrostaticPressure>(o.number("from", 0.5, 0, 1));
    } else if (spec.name == "free_fall") {
        metric = std::make_unique<FreeFall>();
    } else if (spec.name == "cube_shape") {
        metric = std::make_unique<CubeShape>();
    } else if (spec.name == "poiseuille") {
        metric = std::make_unique<Poiseuille>(o.number("gap", 0.1, 1e-6, 1e6),
                                              o.number("from", 0.5, 0, 1),
                                              o.number("x_window", 0.1, 0, 1e6),
                                              o.number("z_window", 0.03, 0, 1e6));
    } else if (spec.name == "surge_front") {
        metric = std::make_unique<Front>("surge_front", "liquid",
                                         o.direction("direction", Vec3(1, 0, 0)),
                                         o.number("percentile", 99, 50, 100));
    } else if (spec.name == "plume_rise") {
        metric = std::make_unique<Front>("plume_rise", "gas", o.direction("up", Vec3(0, 1, 0)),
                                         o.number("percentile", 95, 50, 100));
    } else {
        std::string names;
        for (const std::string& n : metricNames()) names += (names.empty() ? "" : ", ") + n;
        throw SceneError(
            msg(where, " = \"", spec.name, "\": unknown metric (expected one of ", names, ")"));
    }
    o.finish();
    return metric;
}

TraceError compareTraces(const std::vector<double>& trace, const std::vector<double>& reference)
{
    const std::size_t n = std::min(trace.size(), reference.size());
    double sq = 0, origin = NAN, excursion = 0;
    std::size_t count = 0;
    for (std::size_t k = 0; k < n; ++k) {
        if (!std::isfinite(reference[k])) continue;
        if (std::isnan(origin)) origin = reference[k];
        excursion = std::max(excursion, std::abs(reference[k] - origin));
        if (!std::isfinite(trace[k])) continue;
        sq += (trace[k] - reference[k]) * (trace[k] - reference[k]);
        ++count;
    }
    TraceError e{NAN, NAN};
    if (count == 0) return e;
    e.rms = std::sqrt(sq / double(count));
    if (excursion > 0) e.relative = e.rms / excursion;
    return e;
}

} // namespace cmd
} // namespace ghostfx
