/// @file   ScriptInputs.cc
/// @brief  A script's additions to a scene into checkpoint attachments and back (ScriptInputs.h).
#include "ScriptInputs.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <nlohmann/json.hpp>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <limits>
#include <sstream>

namespace ghostfx {
namespace python {

using Json = nlohmann::json;
using sph::Real;

namespace {

constexpr const char* INPUTS = "script_inputs.json";
constexpr const char* SHAPES = "script_shapes.vdb";

Json vec(const sph::Vec3d& v) { return Json::array({v[0], v[1], v[2]}); }
sph::Vec3d vec(const Json& j) { return sph::Vec3d(j.at(0), j.at(1), j.at(2)); }
/// JSON has no infinity: an open end is null.
Json endTime(double t) { return std::isfinite(t) ? Json(t) : Json(nullptr); }
double endTime(const Json& j)
{
    return j.is_null() ? std::numeric_limits<double>::infinity() : j.get<double>();
}

/// Every shape written once, in the order met; entries name them by index.
struct ShapeWriter
{
    openvdb::GridPtrVec grids;
    Json entry(const vdbio::SceneShape& s)
    {
        openvdb::FloatGrid::Ptr grid = sph::gridOf(s.shape)->deepCopy();
        grid->setName("shape_" + std::to_string(grids.size()));
        grids.push_back(grid);
        return Json{{"name", s.name},
                    {"geometry", s.geometry},
                    {"shape_name", s.shape.name()},
                    {"shape", grids.size() - 1}};
    }
};

Json solidVelocity(std::size_t index, const SolidVelocity& v)
{
    Json rotation = Json::array();
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) rotation.push_back(double(v.start.rotation(r, c)));
    }
    return Json{{"solid", index},
                {"time", v.time},
                {"rotation", rotation},
                {"translation", vec(sph::Vec3d(v.start.translation))},
                {"velocity", vec(v.velocity)}};
}

/// Motion keys as {time, translate, rotate} objects (rotate in degrees, as in a scene).
Json keysJson(const sph::KeyedMotion& motion)
{
    Json keys = Json::array();
    for (const sph::RigidKey& k : motion.keys) {
        keys.push_back(
            {{"time", k.time}, {"translate", vec(k.translate)}, {"rotate", vec(k.rotateDegrees)}});
    }
    return keys;
}

/// A dynamic solid's making: density or mass, initial velocities, material.
Json bodyJson(const vdbio::SceneDynamic& b)
{
    return Json{{"density", b.density},         {"mass", b.mass},
                {"velocity", vec(b.velocity)},  {"angular_velocity", vec(b.angularVelocity)},
                {"restitution", b.restitution}, {"friction", b.friction}};
}

vdbio::SceneDynamic readBody(const Json& j)
{
    vdbio::SceneDynamic b;
    b.density = j.at("density");
    b.mass = j.at("mass");
    b.velocity = vec(j.at("velocity"));
    b.angularVelocity = vec(j.at("angular_velocity"));
    b.restitution = j.at("restitution");
    b.friction = j.at("friction");
    return b;
}

Json inputsJson(const ScriptInputs& in, ShapeWriter& shapes)
{
    Json doc{{"solids", Json::array()},
             {"emitters", Json::array()},
             {"gas_sources", Json::array()},
             {"solid_velocities", Json::array()}};
    for (const vdbio::SceneSolid& s : in.solids) {
        Json e = shapes.entry(s);
        e.update({{"velocity", vec(s.velocity)}, {"keys", keysJson(s.motion)}});
        if (s.dynamic) e["dynamic"] = bodyJson(*s.dynamic);
        doc["solids"].push_back(e);
    }
    for (const vdbio::SceneEmitter& s : in.emitters) {
        Json e = shapes.entry(s);
        e.update({{"velocity", vec(s.velocity)},
                  {"start", s.start},
                  {"end", endTime(s.end)},
                  {"keys", keysJson(s.motion)}});
        doc["emitters"].push_back(e);
    }
    for (const vdbio::SceneGasSource& s : in.gasSources) {
        Json e = shapes.entry(s);
        e.update({{"velocity", vec(s.velocity)},
                  {"temperature", s.temperature},
                  {"rate", s.rate},
                  {"start", s.start},
                  {"end", endTime(s.end)},
                  {"keys", keysJson(s.motion)}});
        doc["gas_sources"].push_back(e);
    }
    for (const auto& [index, v] : in.velocities)
        doc["solid_velocities"].push_back(solidVelocity(index, v));
    return doc;
}

/// The shapes of the attachment SHAPES, by index.
std::vector<openvdb::FloatGrid::Ptr> readShapes(const std::string& bytes)
{
    std::istringstream in(bytes, std::ios::binary);
    openvdb::io::Stream stream(in);
    std::vector<openvdb::FloatGrid::Ptr> out;
    for (const openvdb::GridBase::Ptr& g : *stream.getGrids()) {
        auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(g);
        if (!grid) throw IoError("a shape is not a float grid");
        out.push_back(grid);
    }
    return out;
}

template <typename Entry>
Entry shapedEntry(const Json& e, const std::vector<openvdb::FloatGrid::Ptr>& shapes)
{
    const std::size_t k = e.at("shape");
    if (k >= shapes.size()) throw IoError("an entry names a shape that is not stored");
    return Entry(e.at("name"), e.at("geometry"),
                 sph::makeLevelSet(shapes[k], e.at("shape_name").get<std::string>()));
}

SolidVelocity readSolidVelocity(const Json& e)
{
    SolidVelocity v;
    v.time = e.at("time");
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
            v.start.rotation(r, c) = Real(e.at("rotation").at(3 * r + c).get<double>());
    }
    v.start.translation = sph::Vec3(vec(e.at("translation")));
    v.velocity = vec(e.at("velocity"));
    return v;
}

sph::KeyedMotion readKeys(const Json& entry)
{
    sph::KeyedMotion motion;
    for (const Json& k : entry.at("keys")) {
        motion.keys.push_back(
            {k.at("time").get<double>(), vec(k.at("translate")), vec(k.at("rotate"))});
    }
    return motion;
}

/// An emitter or gas source entry: its shape, velocity, start and end times and motion keys.
template <typename Entry>
Entry timedEntry(const Json& e, const std::vector<openvdb::FloatGrid::Ptr>& shapes)
{
    Entry s = shapedEntry<Entry>(e, shapes);
    s.velocity = vec(e.at("velocity"));
    s.start = e.at("start");
    s.end = endTime(e.at("end"));
    s.motion = readKeys(e);
    return s;
}

ScriptInputs readInputs(const Json& doc, const std::vector<openvdb::FloatGrid::Ptr>& shapes)
{
    ScriptInputs in;
    for (const Json& e : doc.at("solids")) {
        vdbio::SceneSolid s = shapedEntry<vdbio::SceneSolid>(e, shapes);
        s.velocity = vec(e.at("velocity"));
        s.motion = readKeys(e);
        if (e.contains("dynamic")) s.dynamic = readBody(e.at("dynamic"));
        in.solids.push_back(s);
    }
    for (const Json& e : doc.at("emitters"))
        in.emitters.push_back(timedEntry<vdbio::SceneEmitter>(e, shapes));
    for (const Json& e : doc.at("gas_sources")) {
        auto s = timedEntry<vdbio::SceneGasSource>(e, shapes);
        s.temperature = e.at("temperature");
        s.rate = e.at("rate");
        in.gasSources.push_back(s);
    }
    for (const Json& e : doc.at("solid_velocities")) {
        in.velocities[e.at("solid").get<std::size_t>()] = readSolidVelocity(e);
    }
    return in;
}

} // namespace

sph::RigidMotion SolidVelocity::motion() const
{
    const sph::RigidTransform from = start;
    const sph::Vec3d p0(from.translation), v = velocity;
    const double t0 = time;
    return [from, p0, v, t0](double t) {
        sph::RigidTransform xf = from;
        xf.translation = sph::Vec3(p0 + v * (t - t0));
        xf.translationRate = sph::Vec3(v);
        xf.rotationRate = openvdb::math::Mat3<Real>::zero();
        xf.hasRates = true;
        return xf;
    };
}

vdbio::CheckpointAttachments toAttachments(const ScriptInputs& inputs)
{
    if (inputs.empty()) return {};
    ShapeWriter shapes;
    const Json doc = inputsJson(inputs, shapes);
    std::ostringstream vdb(std::ios::binary);
    openvdb::io::Stream(vdb).write(shapes.grids);
    return {{INPUTS, doc.dump()}, {SHAPES, vdb.str()}};
}

ScriptInputs fromAttachments(const vdbio::CheckpointAttachments& attachments,
                             const std::string& path)
{
    const auto inputs = attachments.find(INPUTS);
    if (inputs == attachments.end()) return {};
    const auto shapes = attachments.find(SHAPES);
    try {
        if (shapes == attachments.end()) throw IoError(std::string("no attachment ") + SHAPES);
        return readInputs(Json::parse(inputs->second), readShapes(shapes->second));
    } catch (const std::exception& e) {
        throw IoError(msg("checkpoint '", path, "': the script's additions (attachments ", INPUTS,
                          ", ", SHAPES, ") cannot be read back: ", e.what()));
    }
}

} // namespace python
} // namespace ghostfx
