/// @file   Readers.cc
/// @brief  Python readers of what ghostfx writes, as NumPy arrays: the points of a .vdb
///         (vdbio::readPoints), a volume grid dense or as active voxels (vdbio::readDenseVolume,
///         vdbio::readActiveVoxels), a stats.h5 (vdbio::readStats) and a checkpoint
///         (vdbio::readCheckpointStates). No h5py or pyopenvdb is needed.
/// @details Arrays are copies in the type the file stores (float32 attributes stay float32,
///          int64 ids stay int64), except point positions "P", which are world positions in
///          float64 (see vdbio/Readers.h). The reads release the GIL.
#include "Readers.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/Readers.h>
#include <ghostfx/vdbio/Stats.h>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <string>
#include <vector>

namespace py = pybind11;
using namespace ghostfx;

namespace {

/// A column as an array: (rows,) for scalars, (rows, 3) for vectors, then reshaped to `shape`
/// if given (the dense volume's (nx, ny, nz)).
py::array toArray(const vdbio::Column& column, std::vector<py::ssize_t> shape = {})
{
    if (shape.empty()) shape.push_back(py::ssize_t(column.rows));
    if (column.components > 1) shape.push_back(column.components);
    // No base object: pybind11 copies the bytes into the new array.
    return py::array(py::dtype(vdbio::scalarTypeName(column.scalar)), shape, column.bytes.data());
}

/// A read volume: dense (values over the active box) or active voxels (ijk, world, values).
struct PyVolume
{
    std::string grid, valueType, gridClass;
    bool active = false;
    double voxelSize = 0;
    std::array<double, 3> voxelSizes{};
    py::object background, transform, values;
    py::dict metadata;
    py::object origin = py::none(), indexMin = py::none(), ijk = py::none(), world = py::none();
};

void fillHeader(PyVolume& v, const vdbio::VolumeHeader& h)
{
    v.grid = h.grid;
    v.valueType = h.valueType;
    v.gridClass = h.gridClass;
    v.voxelSize = h.voxelSize[0];
    v.voxelSizes = h.voxelSize;
    v.background = toArray(h.background)[py::int_(0)];
    py::array_t<double> m({4, 4});
    std::copy(h.indexToWorld.begin(), h.indexToWorld.end(), m.mutable_data());
    v.transform = m;
    for (const vdbio::VolumeHeader::Meta& meta : h.metadata) {
        const std::string& t = meta.type;
        py::object value = py::str(meta.text);
        if (t == "float" || t == "double") value = py::float_(std::stod(meta.text));
        else if (t == "int32" || t == "int64") value = py::int_(std::stoll(meta.text));
        else if (t == "bool") value = py::bool_(meta.text == "true" || meta.text == "1");
        v.metadata[py::str(meta.name)] = value;
    }
}

PyVolume readVolume(const std::string& file, const std::string& grid, bool active)
{
    PyVolume v;
    v.active = active;
    if (active) {
        vdbio::ActiveVoxels a;
        {
            py::gil_scoped_release release;
            a = vdbio::readActiveVoxels(file, grid, "read_volume");
        }
        fillHeader(v, a.header);
        const py::ssize_t n = py::ssize_t(a.ijk.size());
        py::array_t<std::int32_t> ijk({n, py::ssize_t(3)});
        py::array_t<double> world({n, py::ssize_t(3)});
        for (py::ssize_t r = 0; r < n; ++r) {
            for (int c = 0; c < 3; ++c) {
                ijk.mutable_at(r, c) = a.ijk[std::size_t(r)][std::size_t(c)];
                world.mutable_at(r, c) = a.world[std::size_t(r)][std::size_t(c)];
            }
        }
        v.ijk = ijk;
        v.world = world;
        v.values = toArray(a.values);
        return v;
    }
    vdbio::DenseVolume d;
    {
        py::gil_scoped_release release;
        d = vdbio::readDenseVolume(file, grid, "read_volume");
    }
    fillHeader(v, d.header);
    v.values = toArray(d.values, {d.dims[0], d.dims[1], d.dims[2]});
    v.origin = py::make_tuple(d.origin[0], d.origin[1], d.origin[2]);
    v.indexMin = py::make_tuple(d.indexMin[0], d.indexMin[1], d.indexMin[2]);
    return v;
}

/// World positions of grid index coordinates: [i j k 1] times the 4x4 transform.
py::array_t<double> indexToWorld(const PyVolume& v,
                                 py::array_t<double, py::array::c_style | py::array::forcecast> ijk)
{
    const bool single = ijk.ndim() == 1;
    const py::array_t<double, py::array::c_style | py::array::forcecast> points =
        single ? py::array_t<double, py::array::c_style | py::array::forcecast>(
                     ijk.reshape({py::ssize_t(1), ijk.shape(0)}))
               : ijk;
    if (points.ndim() != 2 || points.shape(1) != 3) {
        throw ValueError("Volume.index_to_world: expected index coordinates of shape (3,) or (N, 3)");
    }
    const auto m = v.transform.cast<py::array_t<double>>().unchecked<2>();
    const auto p = points.unchecked<2>();
    py::array_t<double> out({p.shape(0), py::ssize_t(3)});
    auto w = out.mutable_unchecked<2>();
    for (py::ssize_t r = 0; r < p.shape(0); ++r) {
        for (int c = 0; c < 3; ++c)
            w(r, c) = p(r, 0) * m(0, c) + p(r, 1) * m(1, c) + p(r, 2) * m(2, c) + m(3, c);
    }
    if (single) return out.reshape({py::ssize_t(3)});
    return out;
}

py::dict readPoints(const std::string& file, py::object grid)
{
    vdbio::PointsData data;
    {
        const std::string name = grid.is_none() ? std::string() : grid.cast<std::string>();
        py::gil_scoped_release release;
        data = vdbio::readPoints(file, name, "read_points");
    }
    py::dict out;
    for (const vdbio::Column& column : data.columns) out[py::str(column.name)] = toArray(column);
    return out;
}

py::dict readStats(const std::string& file)
{
    vdbio::StatsTable table;
    {
        py::gil_scoped_release release;
        table = vdbio::readStats(file);
    }
    py::dict out;
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
        py::array_t<double> a(py::ssize_t(table.rows.size()));
        for (std::size_t r = 0; r < table.rows.size(); ++r) a.mutable_at(py::ssize_t(r)) = table.rows[r][c];
        out[py::str(table.columns[c])] = a;
    }
    return out;
}

template <typename T, typename S>
py::array_t<T> scalars(const std::vector<S>& v)
{
    py::array_t<T> a(py::ssize_t(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i) a.mutable_at(py::ssize_t(i)) = T(v[i]);
    return a;
}

/// (N, 3) in the build's precision (the checkpoint's Real), as the checkpoint stores them.
py::array_t<sph::Real> triples(const std::vector<sph::Vec3>& v)
{
    py::array_t<sph::Real> a({py::ssize_t(v.size()), py::ssize_t(3)});
    for (std::size_t i = 0; i < v.size(); ++i) {
        for (int c = 0; c < 3; ++c) a.mutable_at(py::ssize_t(i), c) = v[i][c];
    }
    return a;
}

py::dict particleArrays(const sph::ParticleSet& p)
{
    py::dict d;
    d["position"] = triples(p.positions());
    d["velocity"] = triples(p.velocities());
    d["mass"] = scalars<sph::Real>(p.masses());
    d["density"] = scalars<sph::Real>(p.densities());
    d["pressure"] = scalars<sph::Real>(p.pressures());
    std::vector<std::uint8_t> kinds(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) kinds[i] = std::uint8_t(p.kinds()[i]);
    d["kind"] = scalars<std::uint8_t>(kinds);
    d["id"] = scalars<std::int64_t>(p.ids());
    for (const std::string& name : p.scalarChannelNames())
        d[py::str(name)] = scalars<sph::Real>(p.scalarChannel(name));
    for (const std::string& name : p.vectorChannelNames())
        d[py::str(name)] = triples(p.vectorChannel(name));
    return d;
}

py::list readCheckpoint(const std::string& file)
{
    std::vector<sph::SolverState> states;
    {
        py::gil_scoped_release release;
        states = vdbio::readCheckpointStates(file, /*expectedSettingsJson=*/"");
    }
    py::list out;
    for (const sph::SolverState& s : states) {
        py::dict state;
        state["solver"] = s.solver;
        state["particles"] = particleArrays(s.particles);
        state["reals"] = s.reals;
        state["integers"] = s.integers;
        out.append(state);
    }
    return out;
}

void bindVolume(py::module_& m)
{
    py::class_<PyVolume>(m, "Volume",
                         "A volume grid read by read_volume: dense (values over the box of its "
                         "active voxels) or its active voxels (ijk, world, values)")
        .def_readonly("grid", &PyVolume::grid, "the grid's name")
        .def_readonly("value_type", &PyVolume::valueType, "OpenVDB's value type: 'float', 'vec3s'...")
        .def_readonly("grid_class", &PyVolume::gridClass,
                      "'level set' (signed distance, m, negative inside), 'fog volume', "
                      "'staggered' or 'unknown'")
        .def_readonly("active", &PyVolume::active, "True for the active-voxel form")
        .def_readonly("voxel_size", &PyVolume::voxelSize, "voxel size (m) along x")
        .def_readonly("voxel_sizes", &PyVolume::voxelSizes, "voxel size (m) along x, y, z")
        .def_readonly("background", &PyVolume::background,
                      "the value outside the active voxels (a level set's: its narrow-band "
                      "half-width, m)")
        .def_readonly("metadata", &PyVolume::metadata,
                      "the grid's metadata: name -> float, int, bool or str (e.g. 'units', "
                      "'rest_density' in kg/m^3 on ghostfx's density grid)")
        .def_readonly("transform", &PyVolume::transform,
                      "4x4 float64, grid index to world (m) for row vectors: world = [i, j, k, "
                      "1] @ transform")
        .def_readonly("values", &PyVolume::values,
                      "dense: (nx, ny, nz) array, (nx, ny, nz, 3) for vectors, values[i, j, k] at "
                      "grid index index_min + (i, j, k); active: (N,) or (N, 3), one per voxel")
        .def_readonly("origin", &PyVolume::origin,
                      "dense: world position (m) of values[0, 0, 0] (a voxel centre); None for "
                      "active voxels")
        .def_readonly("index_min", &PyVolume::indexMin,
                      "dense: grid index of values[0, 0, 0]; None for active voxels")
        .def_readonly("ijk", &PyVolume::ijk,
                      "active: (N, 3) int32 grid indices of the active voxels (tiles expanded); "
                      "None when dense")
        .def_readonly("world", &PyVolume::world,
                      "active: (N, 3) float64 world positions (m) of their centres; None when "
                      "dense")
        .def("index_to_world", &indexToWorld, py::arg("ijk"),
             "World positions (m) of grid index coordinates, shape (3,) or (N, 3) (fractional "
             "indices allowed); values[i, j, k] of a dense volume is at "
             "index_to_world(index_min + (i, j, k))");
}

} // namespace

void bindReaders(py::module_& m)
{
    bindVolume(m);
    m.def("read_points", &readPoints, py::arg("file"), py::arg("grid") = py::none(),
          "The points of the point grid `grid` of a .vdb (default: its first point grid), as a "
          "dict of attribute name -> NumPy array, one row per point in the same order in every "
          "array: 'P' world positions (m), (N, 3) float64; the others in their stored type, "
          "e.g. 'v' (m/s) (N, 3) float32, 'id' int64, 'density' (kg/m^3) and 'pressure' (Pa) "
          "float32, 'kind' int32; groups as bool arrays 'group:<name>'. A missing file raises "
          "OSError, a missing grid or one that is not a point grid ValueError, naming both");
    m.def("read_volume", &readVolume, py::arg("file"), py::arg("grid"), py::arg("active") = false,
          "The volume grid `grid` of a .vdb (float, double, int32, int64, bool, vec3s, vec3d or "
          "vec3i values; as ghostfx writes them: surface in m (signed distance), density as "
          "rho/rho0 (times metadata['rest_density'] for kg/m^3), vel in m/s) "
          "as a Volume: dense over the box of its active voxels, or with active=True its active "
          "voxels (ijk, world, values)");
    m.def("read_stats", &readStats, py::arg("file"),
          "A statistics file (stats.h5 of `ghostfx run`) as a dict of column name -> float64 "
          "array, one entry per step: the columns Simulation.statistics() gives (time and dt in "
          "s, speeds in m/s, count_* counts, t_* wall-clock seconds)");
    m.def("read_checkpoint", &readCheckpoint, py::arg("file"),
          "The solver states of a checkpoint (.h5) as a list of dicts, one per solver: "
          "'solver' (name), 'particles' (name -> array: 'position' m and 'velocity' m/s (N, 3), "
          "'mass' kg, 'density' kg/m^3, 'pressure' Pa, 'kind' uint8, 'id' int64, and every "
          "named channel; floats in the build's precision), 'reals' and 'integers' (the "
          "solver's scalars, e.g. 'time' in s, 'step')");
}
