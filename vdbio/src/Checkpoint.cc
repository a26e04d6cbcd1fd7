/// @file   Checkpoint.cc
/// @brief  HDF5 checkpoints of a solver state (layout in Checkpoint.h), HDF5 1.10 C++ API.
#include <ghostfx/vdbio/Checkpoint.h>

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <H5Cpp.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <set>
#include <type_traits>

namespace ghostfx {
namespace vdbio {

using sph::ParticleKind;
using sph::ParticleSet;
using sph::Real;
using sph::SolverState;
using sph::Vec3;

namespace {

constexpr const char* FORMAT = "ghostfx checkpoint";
constexpr const char* PARTICLES = "particles";
constexpr const char* SCALARS = "scalar";
constexpr const char* VECTORS = "vector";
constexpr const char* REALS = "reals";
constexpr const char* INTEGERS = "integers";
constexpr const char* ATTACHMENTS = "attachments";
/// The particle kinds a file may hold (ParticleKind values 0 .. KIND_COUNT - 1).
constexpr int KIND_COUNT = 5;

static_assert(sizeof(Vec3) == 3 * sizeof(Real), "Vec3 must be three packed Reals");
static_assert(sizeof(ParticleKind) == 1, "kinds are stored as uint8");

const char* realName() { return std::is_same_v<Real, float> ? "float" : "double"; }

const H5::PredType& realType()
{
    return std::is_same_v<Real, float> ? H5::PredType::NATIVE_FLOAT : H5::PredType::NATIVE_DOUBLE;
}

H5::StrType stringType() { return H5::StrType(H5::PredType::C_S1, H5T_VARIABLE); }

/// HDF5 prints its error stack to stderr by default; we turn its exceptions into one line.
void quietHdf5() { H5::Exception::dontPrint(); }

std::string detailOf(const H5::Exception& e)
{
    std::string detail = e.getDetailMsg();
    return detail.empty() ? std::string("HDF5 error") : detail;
}

// Writing -----------------------------------------------------------------------------------

template <typename T>
void writeScalarAttribute(H5::H5Object& object, const std::string& name, const H5::PredType& type,
                          const T& value)
{
    H5::Attribute attr = object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
    attr.write(type, &value);
}

void writeStringAttribute(H5::H5Object& object, const std::string& name, const std::string& value)
{
    const H5::StrType type = stringType();
    H5::Attribute attr = object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
    attr.write(type, value);
}

/// One dataset of `rows` x `columns` values (columns 1: a 1-D dataset), stored in `type`.
void writeDataset(H5::Group& group, const std::string& name, const H5::PredType& type,
                  const void* data, std::size_t rows, std::size_t columns)
{
    const hsize_t dims[2] = {hsize_t(rows), hsize_t(columns)};
    H5::DataSpace space(columns == 1 ? 1 : 2, dims);
    H5::DataSet set = group.createDataSet(name, type, space);
    if (rows > 0) set.write(data, type); // nothing to write for an empty set
}

/// One state's particles and scalars into `group` (the file's root for the first state):
/// `solver`, `particle_count`, `next_id`, and the groups particles, reals and integers.
void writeStateGroup(H5::Group& group, const SolverState& state)
{
    const ParticleSet& p = state.particles;
    const std::size_t n = p.size();
    writeStringAttribute(group, "solver", state.solver);
    writeScalarAttribute(group, "particle_count", H5::PredType::NATIVE_UINT64, std::uint64_t(n));
    writeScalarAttribute(group, "next_id", H5::PredType::NATIVE_INT64, std::int64_t(p.nextId()));

    H5::Group particles = group.createGroup(PARTICLES);
    writeDataset(particles, "position", realType(), p.positions().data(), n, 3);
    writeDataset(particles, "velocity", realType(), p.velocities().data(), n, 3);
    writeDataset(particles, "mass", realType(), p.masses().data(), n, 1);
    writeDataset(particles, "density", realType(), p.densities().data(), n, 1);
    writeDataset(particles, "pressure", realType(), p.pressures().data(), n, 1);
    writeDataset(particles, "kind", H5::PredType::NATIVE_UINT8, p.kinds().data(), n, 1);
    writeDataset(particles, "id", H5::PredType::NATIVE_INT64, p.ids().data(), n, 1);

    H5::Group scalars = particles.createGroup(SCALARS);
    for (const std::string& name : p.scalarChannelNames()) {
        writeDataset(scalars, name, realType(), p.scalarChannel(name).data(), n, 1);
        H5::DataSet set = scalars.openDataSet(name);
        writeScalarAttribute(set, "default", realType(), p.scalarChannelDefault(name));
    }
    H5::Group vectors = particles.createGroup(VECTORS);
    for (const std::string& name : p.vectorChannelNames()) {
        writeDataset(vectors, name, realType(), p.vectorChannel(name).data(), n, 3);
        H5::DataSet set = vectors.openDataSet(name);
        const Vec3 value = p.vectorChannelDefault(name);
        const hsize_t three = 3;
        H5::Attribute attr = set.createAttribute("default", realType(), H5::DataSpace(1, &three));
        attr.write(realType(), value.asPointer());
    }

    H5::Group reals = group.createGroup(REALS);
    for (const auto& [key, value] : state.reals) {
        writeScalarAttribute(reals, key, H5::PredType::NATIVE_DOUBLE, value);
    }
    H5::Group integers = group.createGroup(INTEGERS);
    for (const auto& [key, value] : state.integers) {
        writeScalarAttribute(integers, key, H5::PredType::NATIVE_INT64, value);
    }
}

/// The file's root attributes (Checkpoint.h), from the first state.
void writeHeader(H5::H5File& h5, const SolverState& state, std::size_t stateCount,
                 const std::string& settingsJson, int frame)
{
    writeStringAttribute(h5, "format", FORMAT);
    writeScalarAttribute(h5, "schema_version", H5::PredType::NATIVE_INT, CHECKPOINT_SCHEMA_VERSION);
    writeStringAttribute(h5, "real", realName());
    writeStringAttribute(h5, "settings", settingsJson);
    writeScalarAttribute(h5, "frame", H5::PredType::NATIVE_INT, frame);
    writeScalarAttribute(h5, "state_count", H5::PredType::NATIVE_INT, int(stateCount));
    const auto time = state.reals.find("time");
    writeScalarAttribute(h5, "time", H5::PredType::NATIVE_DOUBLE,
                         time == state.reals.end() ? 0.0 : time->second);
    const auto step = state.integers.find("step");
    writeScalarAttribute(h5, "step", H5::PredType::NATIVE_INT64,
                         step == state.integers.end() ? std::int64_t(0) : step->second);
    for (int k = 0; k < KIND_COUNT; ++k) {
        const std::uint64_t count = state.particles.count(ParticleKind(k));
        writeScalarAttribute(h5, std::string("count_") + sph::kindName(ParticleKind(k)),
                             H5::PredType::NATIVE_UINT64, count);
    }
}

/// The group of state `k` >= 1 ("state_1", ...); the first state is the root.
std::string stateGroupName(std::size_t k) { return msg("state_", k); }

/// `count` states from `states` on into a new checkpoint at `path` (atomically).
void writeStates(const std::string& path, const SolverState* states, std::size_t count,
                 const std::string& settingsJson, int frame,
                 const CheckpointAttachments& attachments = {})
{
    if (count == 0) throw ValueError(msg("checkpoint '", path, "': no solver state to write"));
    quietHdf5();
    writeAtomically(path, [&](const std::string& tmp) {
        try {
            H5::H5File h5(tmp, H5F_ACC_TRUNC);
            writeHeader(h5, states[0], count, settingsJson, frame);
            writeStateGroup(h5, states[0]);
            for (std::size_t k = 1; k < count; ++k) {
                H5::Group group = h5.createGroup(stateGroupName(k));
                writeStateGroup(group, states[k]);
            }
            if (!attachments.empty()) {
                H5::Group group = h5.createGroup(ATTACHMENTS);
                for (const auto& [name, bytes] : attachments) {
                    writeDataset(group, name, H5::PredType::NATIVE_UINT8, bytes.data(),
                                 bytes.size(), 1);
                }
            }
        } catch (const H5::Exception& e) {
            throw IoError(msg("checkpoint '", path, "': cannot write it (", detailOf(e), ")"));
        }
    });
}

// Reading -----------------------------------------------------------------------------------

/// An open checkpoint file with the path for messages.
struct Reader
{
    std::string path;
    H5::H5File file;

    [[noreturn]] void fail(const std::string& what) const
    {
        throw IoError(msg("checkpoint '", path, "': ", what));
    }

    bool has(const std::string& name) const { return file.attrExists(name); }

    std::string readString(const H5::H5Object& object, const std::string& name) const
    {
        if (!object.attrExists(name)) fail(msg("missing attribute '", name, "'"));
        H5::Attribute attr = object.openAttribute(name);
        if (attr.getTypeClass() != H5T_STRING) fail(msg("attribute '", name, "' is not a string"));
        std::string value;
        attr.read(attr.getStrType(), value);
        return value;
    }

    /// A scalar numeric attribute converted to T by HDF5 (integer to integer, float to float).
    template <typename T>
    T readNumber(const H5::H5Object& object, const std::string& name, const H5::PredType& type,
                 H5T_class_t expectedClass) const
    {
        if (!object.attrExists(name)) fail(msg("missing attribute '", name, "'"));
        H5::Attribute attr = object.openAttribute(name);
        if (attr.getTypeClass() != expectedClass || attr.getSpace().getSimpleExtentNpoints() != 1) {
            fail(msg("attribute '", name, "' is not a single ",
                     expectedClass == H5T_FLOAT ? "floating-point" : "integer", " value"));
        }
        T value{};
        attr.read(type, &value);
        return value;
    }

    std::int64_t readInteger(const H5::H5Object& object, const std::string& name) const
    {
        return readNumber<std::int64_t>(object, name, H5::PredType::NATIVE_INT64, H5T_INTEGER);
    }

    double readDouble(const H5::H5Object& object, const std::string& name) const
    {
        return readNumber<double>(object, name, H5::PredType::NATIVE_DOUBLE, H5T_FLOAT);
    }

    /// Read dataset `name` of `rows` x `columns` values into `data`, checking its shape and that
    /// its values have the class and size of `type` (so nothing is converted on the way).
    void readDataset(const H5::Group& group, const std::string& where, const std::string& name,
                     const H5::PredType& type, H5T_class_t typeClass, void* data, std::size_t rows,
                     std::size_t columns) const
    {
        const std::string full = where + "/" + name;
        if (!group.nameExists(name)) fail(msg("missing dataset '", full, "'"));
        H5::DataSet set = group.openDataSet(name);
        const H5::DataType stored = set.getDataType();
        if (set.getTypeClass() != typeClass || stored.getSize() != type.getSize()) {
            fail(msg("dataset '", full, "' holds ", stored.getSize(), "-byte ",
                     set.getTypeClass() == H5T_FLOAT ? "floating-point" : "non-float",
                     " values, expected ", type.getSize(), "-byte ",
                     typeClass == H5T_FLOAT ? "floating-point" : "integer", " values"));
        }
        H5::DataSpace space = set.getSpace();
        const int rank = space.getSimpleExtentNdims();
        hsize_t dims[2] = {0, 0};
        if (rank == 1 || rank == 2) space.getSimpleExtentDims(dims);
        const bool ok = columns == 1 ? (rank == 1 && dims[0] == rows)
                                     : (rank == 2 && dims[0] == rows && dims[1] == columns);
        if (!ok) {
            fail(msg("dataset '", full, "' has shape ",
                     rank == 2 ? msg(dims[0], " x ", dims[1]) : msg(dims[0]), ", expected ",
                     columns == 1 ? msg(rows) : msg(rows, " x ", columns)));
        }
        if (rows > 0) set.read(data, type);
    }
};

/// Open `path` as a ghostfx checkpoint, or throw IoError saying why not.
Reader openCheckpoint(const std::string& path)
{
    quietHdf5();
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::exists(path, ec)) throw IoError(msg("checkpoint '", path, "': no such file"));
    if (!fs::is_regular_file(path, ec)) throw IoError(msg("checkpoint '", path, "': not a file"));
    bool hdf5 = false;
    try {
        hdf5 = H5::H5File::isHdf5(path);
    } catch (const H5::Exception& e) {
        throw IoError(msg("checkpoint '", path, "': cannot read it (", detailOf(e), ")"));
    }
    if (!hdf5) {
        throw IoError(
            msg("checkpoint '", path, "': not an HDF5 file, so not a ghostfx checkpoint"));
    }
    Reader reader{path, H5::H5File()};
    try {
        reader.file.openFile(path, H5F_ACC_RDONLY);
    } catch (const H5::Exception& e) {
        throw IoError(msg("checkpoint '", path, "': cannot open it (", detailOf(e), ")"));
    }
    bool ours = false;
    if (reader.has("format")) {
        H5::Attribute attr = reader.file.openAttribute("format");
        if (attr.getTypeClass() == H5T_STRING) {
            std::string format;
            attr.read(attr.getStrType(), format);
            ours = format == FORMAT;
        }
    }
    if (!ours) {
        reader.fail(msg("not a ghostfx checkpoint (an HDF5 file without the attribute format = \"",
                        FORMAT, "\")"));
    }
    return reader;
}

CheckpointHeader readHeader(const Reader& r)
{
    CheckpointHeader header;
    header.schemaVersion = int(r.readInteger(r.file, "schema_version"));
    // Another schema may lack some of our fields: report what is there.
    const bool strict = header.schemaVersion == CHECKPOINT_SCHEMA_VERSION;
    auto present = [&](const char* name) { return strict || r.has(name); };
    if (present("solver")) header.solver = r.readString(r.file, "solver");
    if (present("settings")) header.settings = r.readString(r.file, "settings");
    if (present("frame")) header.frame = int(r.readInteger(r.file, "frame"));
    if (present("time")) header.time = r.readDouble(r.file, "time");
    if (present("step")) header.step = r.readInteger(r.file, "step");
    // Schema 1 held one state and no count: it is read as schema 2 with one state.
    if (header.schemaVersion == 1) header.stateCount = 1;
    else if (present("state_count")) header.stateCount = int(r.readInteger(r.file, "state_count"));
    for (int k = 0; k < KIND_COUNT; ++k) {
        const std::string kind = sph::kindName(ParticleKind(k));
        if (present(("count_" + kind).c_str())) {
            header.countPerKind[kind] = std::size_t(r.readInteger(r.file, "count_" + kind));
        }
    }
    return header;
}

template <typename Fn>
auto guarded(const std::string& path, Fn&& fn)
{
    try {
        return fn();
    } catch (const H5::Exception& e) {
        throw IoError(msg("checkpoint '", path, "': cannot read it (", detailOf(e), ")"));
    }
}

// Settings comparison -------------------------------------------------------------------------

/// A JSON pointer token: '~' and '/' escaped as RFC 6901 says.
std::string pointerToken(const std::string& key)
{
    std::string out;
    for (char c : key) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

bool firstDifference(const nlohmann::json& there, const nlohmann::json& here,
                     const std::string& path, std::string& out)
{
    const std::string where = path.empty() ? "/" : path;
    if (there.is_object() && here.is_object()) {
        std::set<std::string> keys;
        for (const auto& item : there.items()) keys.insert(item.key());
        for (const auto& item : here.items()) keys.insert(item.key());
        for (const std::string& key : keys) {
            const std::string child = path + "/" + pointerToken(key);
            const bool inThere = there.contains(key), inHere = here.contains(key);
            if (!inThere) {
                out = msg(child, " is missing there, ", here.at(key).dump(), " in this scene");
                return true;
            }
            if (!inHere) {
                out = msg(child, " is ", there.at(key).dump(), " there, missing in this scene");
                return true;
            }
            if (firstDifference(there.at(key), here.at(key), child, out)) return true;
        }
        return false;
    }
    if (there.is_array() && here.is_array()) {
        const std::size_t common = std::min(there.size(), here.size());
        for (std::size_t i = 0; i < common; ++i) {
            if (firstDifference(there[i], here[i], msg(path, "/", i), out)) return true;
        }
        if (there.size() != here.size()) {
            out =
                msg(where, " has ", there.size(), " items there, ", here.size(), " in this scene");
            return true;
        }
        return false;
    }
    if (there == here) return false; // numbers compare by value: 2000 == 2000.0
    out = msg(where, " is ", there.dump(), " there, ", here.dump(), " in this scene");
    return true;
}

/// The most solver states one checkpoint holds (a boiling scene has three).
constexpr int MAX_STATES = 16;

/// The schema, the precision and (unless `expectedSettingsJson` is empty) the settings.
void checkCompatible(const Reader& r, const CheckpointHeader& header,
                     const std::string& expectedSettingsJson)
{
    if (header.schemaVersion < 1 || header.schemaVersion > CHECKPOINT_SCHEMA_VERSION) {
        r.fail(msg("schema version ", header.schemaVersion, ", this ghostfx reads 1 to ",
                   CHECKPOINT_SCHEMA_VERSION));
    }
    const std::string real = r.readString(r.file, "real");
    if (real != realName()) {
        r.fail(msg("written by a build with Real = ", real, ", this ghostfx uses Real = ",
                   realName(), "; resume with a build of the same precision (GHOSTFX_DOUBLE ",
                   real == "double" ? "ON" : "OFF", ")"));
    }
    if (expectedSettingsJson.empty()) return;
    nlohmann::json there;
    try {
        there = nlohmann::json::parse(header.settings);
    } catch (const nlohmann::json::exception&) {
        r.fail("its settings attribute is not valid JSON");
    }
    nlohmann::json here;
    try {
        here = nlohmann::json::parse(expectedSettingsJson);
    } catch (const nlohmann::json::exception& e) {
        throw ValueError(msg("readCheckpoint('", r.path,
                             "'): the expected settings are not valid JSON: ", e.what()));
    }
    std::string difference;
    if (firstDifference(there, here, "", difference)) {
        throw SceneError(
            msg("checkpoint '", r.path, "' was written with different settings: ", difference));
    }
}

/// The named channels of `particles` (`where`: its path, for messages) into `p`.
void readChannels(const Reader& r, const H5::Group& particles, const std::string& where,
                  std::size_t n, ParticleSet& p)
{
    const H5::PredType& rt = realType();
    for (const char* group : {SCALARS, VECTORS}) {
        const bool vector = group == VECTORS;
        const std::string groupPath = where + "/" + group;
        if (!particles.nameExists(group)) r.fail(msg("missing group '", groupPath, "'"));
        const H5::Group channels = particles.openGroup(group);
        for (hsize_t c = 0; c < channels.getNumObjs(); ++c) {
            const std::string name = channels.getObjnameByIdx(c);
            const H5::DataSet set = channels.openDataSet(name);
            if (!set.attrExists("default")) {
                r.fail(msg("dataset '", groupPath, "/", name, "' has no 'default' attribute"));
            }
            H5::Attribute attr = set.openAttribute("default");
            const hssize_t values = attr.getSpace().getSimpleExtentNpoints();
            if (attr.getTypeClass() != H5T_FLOAT || attr.getDataType().getSize() != sizeof(Real)
                || values != (vector ? 3 : 1)) {
                r.fail(msg("dataset '", groupPath, "/", name, "': attribute 'default' is not ",
                           vector ? "3 values" : "one value", " of the build's Real"));
            }
            if (vector) {
                Vec3 value;
                attr.read(rt, value.asPointer());
                auto& data = p.addVectorChannel(name, value);
                r.readDataset(channels, groupPath, name, rt, H5T_FLOAT, data.data(), n, 3);
            } else {
                Real value = 0;
                attr.read(rt, &value);
                auto& data = p.addScalarChannel(name, value);
                r.readDataset(channels, groupPath, name, rt, H5T_FLOAT, data.data(), n, 1);
            }
        }
    }
}

/// The particles of `group` (`prefix`: its path, "" for the root).
ParticleSet readParticles(const Reader& r, const H5::Group& group, const std::string& prefix)
{
    const std::int64_t count = r.readInteger(group, "particle_count");
    if (count < 0) r.fail(msg(prefix, "/particle_count = ", count, ": expected >= 0"));
    const std::size_t n = std::size_t(count);
    const std::string where = prefix + "/" + PARTICLES;
    if (!group.nameExists(PARTICLES)) r.fail(msg("missing group '", where, "'"));
    const H5::Group particles = group.openGroup(PARTICLES);
    const H5::PredType& rt = realType();

    ParticleSet p;
    std::vector<Vec3> positions(n);
    r.readDataset(particles, where, "position", rt, H5T_FLOAT, positions.data(), n, 3);
    p.addBatch(positions, Real(0), ParticleKind::Liquid);
    r.readDataset(particles, where, "velocity", rt, H5T_FLOAT, p.velocities().data(), n, 3);
    r.readDataset(particles, where, "mass", rt, H5T_FLOAT, p.masses().data(), n, 1);
    r.readDataset(particles, where, "density", rt, H5T_FLOAT, p.densities().data(), n, 1);
    r.readDataset(particles, where, "pressure", rt, H5T_FLOAT, p.pressures().data(), n, 1);
    r.readDataset(particles, where, "kind", H5::PredType::NATIVE_UINT8, H5T_INTEGER,
                  p.kinds().data(), n, 1);
    r.readDataset(particles, where, "id", H5::PredType::NATIVE_INT64, H5T_INTEGER,
                  p.ids().data(), n, 1);
    for (std::size_t i = 0; i < n; ++i) {
        if (std::uint8_t(p.kinds()[i]) >= KIND_COUNT) {
            r.fail(msg(where, ": particle ", i, " has unknown kind ", int(p.kinds()[i])));
        }
    }
    readChannels(r, particles, where, n, p);
    try {
        p.setNextId(r.readInteger(group, "next_id"));
    } catch (const ValueError& e) {
        r.fail(e.what());
    }
    return p;
}

/// A schema-1 state of the liquid solver ("ghost" or "basic") with the keys its solver added
/// since, at the values those states were saved with: Tait pressure, matched air weights, one
/// air resampling phase a step, emitters owing nothing and filling at the Poisson radius.
void migrateSchema1(SolverState& state)
{
    if (state.solver != "ghost" && state.solver != "basic") return;
    auto integer = [&](const char* key, std::int64_t value) { state.integers.emplace(key, value); };
    auto real = [&](const std::string& key, double value) { state.reals.emplace(key, value); };
    integer("pressure_dfsph", 0);
    integer("air_weights_complete", 0);
    const auto step = state.integers.find("step");
    integer("air_phase", std::max<std::int64_t>(1, step == state.integers.end() ? 0 : step->second));
    real("air_phase_credit", 0.0);
    const auto emitters = state.integers.find("emitters");
    for (std::int64_t e = 0; emitters != state.integers.end() && e < emitters->second; ++e) {
        real("emitter_credit_" + std::to_string(e), 0.0);
        real("emitter_fill_scale_" + std::to_string(e), 1.0);
    }
}

/// One solver state from `group` (the root, or "/state_k": `prefix`).
SolverState readStateGroup(const Reader& r, const H5::Group& group, const std::string& prefix)
{
    SolverState state;
    state.solver = r.readString(group, "solver");
    state.particles = readParticles(r, group, prefix);
    for (const char* name : {REALS, INTEGERS}) {
        if (!group.nameExists(name)) r.fail(msg("missing group '", prefix, "/", name, "'"));
        const H5::Group values = group.openGroup(name);
        for (int a = 0; a < values.getNumAttrs(); ++a) {
            const std::string key = values.openAttribute(unsigned(a)).getName();
            if (name == REALS) state.reals[key] = r.readDouble(values, key);
            else state.integers[key] = r.readInteger(values, key);
        }
    }
    return state;
}

} // namespace

// Public API ------------------------------------------------------------------------------------

void writeCheckpoint(const std::string& path, const std::vector<SolverState>& states,
                     const std::string& settingsJson, int frame)
{
    writeStates(path, states.data(), states.size(), settingsJson, frame);
}

void writeCheckpoint(const std::string& path, const std::vector<SolverState>& states,
                     const std::string& settingsJson, int frame,
                     const CheckpointAttachments& attachments)
{
    writeStates(path, states.data(), states.size(), settingsJson, frame, attachments);
}

CheckpointAttachments readCheckpointAttachments(const std::string& path)
{
    const Reader r = openCheckpoint(path);
    return guarded(path, [&] {
        CheckpointAttachments out;
        if (!r.file.nameExists(ATTACHMENTS)) return out;
        const H5::Group group = r.file.openGroup(ATTACHMENTS);
        for (hsize_t k = 0; k < group.getNumObjs(); ++k) {
            const std::string name = group.getObjnameByIdx(k);
            H5::DataSet set = group.openDataSet(name);
            hsize_t rows = 0;
            if (set.getSpace().getSimpleExtentNdims() == 1)
                set.getSpace().getSimpleExtentDims(&rows);
            std::string bytes(std::size_t(rows), '\0');
            r.readDataset(group, "/" + std::string(ATTACHMENTS), name, H5::PredType::NATIVE_UINT8,
                          H5T_INTEGER, bytes.data(), bytes.size(), 1);
            out[name] = std::move(bytes);
        }
        return out;
    });
}

void writeCheckpoint(const std::string& path, const SolverState& state,
                     const std::string& settingsJson, int frame)
{
    writeStates(path, &state, 1, settingsJson, frame);
}

CheckpointHeader readCheckpointHeader(const std::string& path)
{
    const Reader reader = openCheckpoint(path);
    return guarded(path, [&] { return readHeader(reader); });
}

std::string firstSettingsDifference(const std::string& thereJson, const std::string& hereJson)
{
    auto parse = [](const std::string& text, const char* which) {
        try {
            return nlohmann::json::parse(text);
        } catch (const nlohmann::json::exception& e) {
            throw ValueError(msg("settings ", which, " are not valid JSON: ", e.what()));
        }
    };
    const nlohmann::json there = parse(thereJson, "of the checkpoint");
    const nlohmann::json here = parse(hereJson, "of this scene");
    std::string out;
    firstDifference(there, here, "", out);
    return out;
}

std::vector<SolverState> readCheckpointStates(const std::string& path,
                                              const std::string& expectedSettingsJson)
{
    const Reader r = openCheckpoint(path);
    return guarded(path, [&] {
        const CheckpointHeader header = readHeader(r);
        checkCompatible(r, header, expectedSettingsJson);
        if (header.stateCount < 1 || header.stateCount > MAX_STATES) {
            r.fail(msg("state_count = ", header.stateCount, ": expected 1 to ", MAX_STATES));
        }
        std::vector<SolverState> states;
        states.push_back(readStateGroup(r, r.file, ""));
        if (header.schemaVersion == 1) migrateSchema1(states.front());
        for (int k = 1; k < header.stateCount; ++k) {
            const std::string name = stateGroupName(std::size_t(k));
            if (!r.file.nameExists(name)) r.fail(msg("missing group '/", name, "'"));
            states.push_back(readStateGroup(r, r.file.openGroup(name), "/" + name));
        }
        return states;
    });
}

SolverState readCheckpoint(const std::string& path, const std::string& expectedSettingsJson)
{
    std::vector<SolverState> states = readCheckpointStates(path, expectedSettingsJson);
    if (states.size() != 1) {
        throw IoError(msg("checkpoint '", path, "': holds ", states.size(),
                          " solver states (a boiling scene's), expected one"));
    }
    return std::move(states.front());
}

namespace detail {

namespace {
template <typename WriteFn>
void patchAttribute(const std::string& path, const std::string& name, WriteFn&& write)
{
    quietHdf5();
    try {
        H5::H5File file(path, H5F_ACC_RDWR);
        if (file.attrExists(name)) file.removeAttr(name);
        write(file);
    } catch (const H5::Exception& e) {
        throw IoError(msg("'", path, "': cannot patch attribute '", name, "' (", detailOf(e), ")"));
    }
}
} // namespace

void patchCheckpointAttribute(const std::string& path, const std::string& name, std::int64_t value)
{
    patchAttribute(path, name, [&](H5::H5File& file) {
        writeScalarAttribute(file, name, H5::PredType::NATIVE_INT64, value);
    });
}

void patchCheckpointAttribute(const std::string& path, const std::string& name,
                              const std::string& value)
{
    patchAttribute(path, name, [&](H5::H5File& file) { writeStringAttribute(file, name, value); });
}

} // namespace detail

} // namespace vdbio
} // namespace ghostfx
