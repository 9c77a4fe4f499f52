// The shared conversions and argument parsers of binding_support.hpp.

#include "binding_support.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "primseg/auto_level.hpp"
#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/primitive.hpp"
#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg::python {
namespace {

template <typename T>
std::vector<Triangle> read_triangles(const ArrayView& a, std::size_t vertex_count) {
  std::vector<Triangle> triangles(static_cast<std::size_t>(a.rows));
  for (py::ssize_t i = 0; i < a.rows; ++i)
    for (py::ssize_t j = 0; j < 3; ++j) {
      const T index = element<T>(a, i, j);
      if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_count)
        throw InvalidInputError(entry("F", i, j) + " = " + std::to_string(index) +
                                " is not a vertex index (V has " + std::to_string(vertex_count) +
                                " rows)");
      triangles[i][j] = static_cast<std::uint32_t>(index);
    }
  return triangles;
}

// Builds the mesh from checked arrays. Called without the GIL: the arrays are kept alive by
// their owners in the caller.
Mesh mesh_from_arrays(const ArrayView& v, const ArrayView& f) {
  if (f.rows == 0) throw InvalidInputError("F has no faces");
  if (v.rows > std::numeric_limits<std::uint32_t>::max() ||
      f.rows > std::numeric_limits<std::uint32_t>::max())
    throw InvalidInputError("V and F must have fewer than 2^32 rows");
  std::vector<Vec3> positions =
      v.itemsize == 4 ? read_vertices<float>(v) : read_vertices<double>(v);
  const std::size_t n = positions.size();
  std::vector<Triangle> triangles;
  if (f.kind == 'i')
    triangles =
        f.itemsize == 4 ? read_triangles<std::int32_t>(f, n) : read_triangles<std::int64_t>(f, n);
  else
    triangles =
        f.itemsize == 4 ? read_triangles<std::uint32_t>(f, n) : read_triangles<std::uint64_t>(f, n);
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

// A Mesh's pickled state: its arrays' bytes, as stored (native byte order: pickles are read on
// machines like the one that wrote them, as numpy's own are).
template <typename T>
py::bytes array_bytes(const std::vector<T>& values) {
  return py::bytes(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

template <typename T>
std::vector<T> array_from_bytes(const py::handle& bytes, const char* what) {
  if (!py::isinstance<py::bytes>(bytes))
    throw InvalidInputError(std::string("Mesh: pickled ") + what + " is not bytes");
  const std::string_view data = bytes.cast<std::string_view>();
  if (data.size() % sizeof(T) != 0)
    throw InvalidInputError(std::string("Mesh: pickled ") + what + " has " +
                            std::to_string(data.size()) + " bytes, not a multiple of " +
                            std::to_string(sizeof(T)));
  std::vector<T> values(data.size() / sizeof(T));
  std::memcpy(values.data(), data.data(), data.size());
  return values;
}

std::vector<PrimitiveType> parse_primitives(const py::object& names) {
  std::vector<std::string> list;
  if (py::isinstance<py::str>(names))
    list.push_back(names.cast<std::string>());
  else
    for (const py::handle& name : names) {
      if (!py::isinstance<py::str>(name))
        throw InvalidInputError("primitives: expected names, got " +
                                py::repr(name).cast<std::string>());
      list.push_back(name.cast<std::string>());
    }
  std::vector<PrimitiveType> types;
  try {
    for (const std::string& name : list) types.push_back(fittable_type_from_string(name));
  } catch (const InvalidInputError& error) {
    throw InvalidInputError(std::string("primitives: ") + error.what());
  }
  return types;
}

// The CLI's default level (--tolerance 0.1%): as a fraction of the bounding-box diagonal.
constexpr double kDefaultRelativeTolerance = 0.1 / 100;

}  // namespace

std::string join_docs(std::initializer_list<std::string> parts) {
  std::string text;
  for (const std::string& part : parts) {
    if (!text.empty()) text += "\n\n";
    text += part;
  }
  return text;
}

std::string cpp_doc(const char* name, const char* text) {
  return std::string("C++ ") + name + ":\n" + text;
}

std::string count_of(std::uint64_t count, const std::string& noun, const std::string& plural) {
  return std::to_string(count) + " " + (count == 1 ? noun : plural.empty() ? noun + "s" : plural);
}

py::array as_numpy_array(const py::handle& object) {
  if (py::isinstance<py::array>(object)) return py::reinterpret_borrow<py::array>(object);
  return py::array(py::module_::import("numpy").attr("asarray")(object));
}

ArrayView view_n_by_3(const py::handle& object, const char* name, const char* accepted,
                      bool floating, py::object& owner) {
  py::array array = as_numpy_array(object);
  const py::dtype dtype = array.dtype();
  const char kind = dtype.kind();
  const py::ssize_t itemsize = dtype.itemsize();
  const bool accepted_type = floating
                                 ? kind == 'f' && (itemsize == 4 || itemsize == 8)
                                 : (kind == 'i' || kind == 'u') && (itemsize == 4 || itemsize == 8);
  if (!accepted_type)
    throw InvalidInputError(std::string(name) + " must be an array of " + accepted + ", not " +
                            py::repr(dtype.attr("name")).cast<std::string>());
  if (!dtype.attr("isnative").cast<bool>())  // byte-swapped data: one converted copy
    array = py::array(array.attr("astype")(dtype.attr("newbyteorder")("=")));
  if (array.ndim() != 2 || array.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d)
      shape += (d ? ", " : "") + std::to_string(array.shape(d));
    shape += array.ndim() == 1 ? ",)" : ")";
    throw InvalidInputError(std::string(name) + " must have shape (n, 3), not " + shape);
  }
  owner = array;
  return {static_cast<const char*>(array.data()),
          array.shape(0),
          array.strides(0),
          array.strides(1),
          kind,
          itemsize};
}

std::string entry(const char* name, py::ssize_t row, py::ssize_t column) {
  return std::string(name) + "[" + std::to_string(row) + ", " + std::to_string(column) + "]";
}

std::shared_ptr<const Mesh> mesh_from_python(const py::handle& vertices, const py::handle& faces) {
  py::object v_owner, f_owner;
  const ArrayView v = view_n_by_3(vertices, "V", "float32 or float64", true, v_owner);
  const ArrayView f = view_n_by_3(faces, "F", "int32, int64, uint32 or uint64", false, f_owner);
  py::gil_scoped_release release;
  return std::make_shared<const Mesh>(mesh_from_arrays(v, f));
}

py::array read_only(py::array array) {
  array.attr("flags").attr("writeable") = false;
  return array;
}

py::tuple mesh_state(const PyMesh& self) {
  const Mesh& mesh = *self.mesh;
  return py::make_tuple(array_bytes(mesh.positions), array_bytes(mesh.polygon_offsets),
                        array_bytes(mesh.polygon_vertices), array_bytes(mesh.triangles),
                        array_bytes(mesh.face_of_triangle));
}

PyMesh mesh_from_state(const py::tuple& state) {
  if (state.size() != 5) throw InvalidInputError("Mesh: not a pickled primseg.Mesh");
  Mesh mesh;
  mesh.positions = array_from_bytes<Vec3>(state[0], "positions");
  mesh.polygon_offsets = array_from_bytes<std::uint32_t>(state[1], "polygon offsets");
  mesh.polygon_vertices = array_from_bytes<std::uint32_t>(state[2], "polygon vertices");
  mesh.triangles = array_from_bytes<Triangle>(state[3], "triangles");
  mesh.face_of_triangle = array_from_bytes<std::uint32_t>(state[4], "face_of_triangle");
  mesh.validate();
  return PyMesh{std::make_shared<const Mesh>(std::move(mesh))};
}

HierarchyOptions hierarchy_options(const py::object& primitives, const std::string& weights,
                                   unsigned threads, bool exact_costs, bool eager,
                                   double merge_batch_tolerance, unsigned regions) {
  HierarchyOptions options;
  options.primitives = parse_primitives(primitives);
  if (weights != "area" && weights != "uniform")
    throw InvalidInputError("weights: must be 'area' or 'uniform', not '" + weights + "'");
  options.weights = weights == "uniform" ? VertexWeights::Uniform : VertexWeights::Area;
  options.threads = threads;
  options.exact_costs = exact_costs;
  options.evaluation = eager ? CandidateEvaluation::Eager : CandidateEvaluation::Lazy;
  options.merge_batch_tolerance = merge_batch_tolerance;
  options.regions = regions;
  validate(options);
  return options;
}

std::function<void(double)> python_progress(const py::object& progress) {
  if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
    throw InvalidInputError("progress must be None or callable, not " +
                            py::repr(progress).cast<std::string>());
  return [progress](double fraction) {
    const py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw PythonErrorPending{};
    if (progress.is_none()) return;
    try {
      progress(fraction);
    } catch (py::error_already_set& error) {
      error.restore();
      throw PythonErrorPending{};
    }
  };
}

void validate_level(const LevelArguments& level, std::uint32_t face_count) {
  if (int(level.k.has_value()) + int(level.tolerance.has_value()) +
          int(level.relative_tolerance.has_value()) >
      1)
    throw InvalidInputError("give at most one of k, tolerance and relative_tolerance");
  if (level.k) {
    if (const auto* name = std::get_if<std::string>(&*level.k)) {
      if (*name != "auto")
        throw InvalidInputError("k must be a number of clusters or 'auto', not '" + *name + "'");
    } else if (const std::int64_t k = std::get<std::int64_t>(*level.k); k < 1 || k > face_count) {
      throw InvalidInputError("k must be between 1 and the number of faces (" +
                              std::to_string(face_count) + "), not " + std::to_string(k));
    }
  }
  if (level.tolerance && !(std::isfinite(*level.tolerance) && *level.tolerance >= 0))
    throw InvalidInputError("tolerance must be a non-negative number, not " +
                            std::to_string(*level.tolerance));
  if (level.relative_tolerance &&
      !(std::isfinite(*level.relative_tolerance) && *level.relative_tolerance >= 0))
    throw InvalidInputError("relative_tolerance must be a non-negative number, not " +
                            std::to_string(*level.relative_tolerance));
}

Segmentation cut_level(const Hierarchy& hierarchy, const LevelArguments& level) {
  validate_level(level, hierarchy.face_count());
  if (level.k) {
    if (std::holds_alternative<std::string>(*level.k))
      return cut_by_count(hierarchy, choose_level(hierarchy).clusters);
    return cut_by_count(hierarchy, static_cast<std::uint32_t>(std::get<std::int64_t>(*level.k)));
  }
  if (level.tolerance) return cut_by_tolerance(hierarchy, *level.tolerance);
  const double fraction = level.relative_tolerance.value_or(kDefaultRelativeTolerance);
  return cut_by_tolerance(hierarchy, fraction * bounding_box_diagonal(hierarchy.mesh()));
}

py::list vector_list(const Vec3& v) {
  py::list list;
  for (double x : v) list.append(x);
  return list;
}

py::dict cluster_dict(const ClusterReport& report) {
  py::dict params;
  for (const NamedParameter& p : named_parameters(report.primitive))
    params[py::str(std::string(p.name))] =
        p.is_vector ? py::object(vector_list(p.value)) : py::object(py::float_(p.value[0]));
  py::dict cluster;
  cluster["id"] = report.id;
  cluster["type"] = std::string(to_string(report.primitive.type));
  cluster["faces"] = report.face_count;
  cluster["area"] = report.area;
  cluster["rms"] = report.rms;
  cluster["max"] = report.max;
  cluster["params"] = params;
  return cluster;
}

py::list relations_list(const std::vector<ClusterRelation>& relations) {
  py::list list;
  for (const ClusterRelation& relation : relations) {
    py::dict related;
    related["kind"] = std::string(to_string(relation.kind));
    related["clusters"] = py::cast(relation.clusters);
    if (relation.kind == ClusterRelation::Kind::Orthogonal)
      related["orthogonal_to"] = py::cast(relation.orthogonal_to);
    related["deviation"] = relation.deviation;
    list.append(related);
  }
  return list;
}

py::dict border_dict(const ClusterBorder& border) {
  py::list curves;
  for (const BorderCurve& curve : border.curves) {
    py::dict c;
    c["closed"] = curve.closed;
    c["vertices"] = py::cast(curve.vertices);
    curves.append(c);
  }
  py::dict d;
  d["clusters"] = py::make_tuple(border.first, border.second == kMeshBoundary
                                                   ? py::object(py::none())
                                                   : py::object(py::int_(border.second)));
  d["edges"] = border.edge_count;
  d["length"] = border.length;
  d["angle"] =
      std::isnan(border.angle) ? py::object(py::none()) : py::object(py::float_(border.angle));
  d["curves"] = curves;
  return d;
}

std::shared_ptr<const Mesh> mesh_argument(const std::string& function, const py::object& first,
                                          const py::object& faces) {
  if (py::isinstance<PyMesh>(first)) {
    if (!faces.is_none())
      throw InvalidInputError(
          function + "(mesh) takes no F" +
          (function == "denoise" || function == "skeleton" ? " (give the level as k=...)" : ""));
    return first.cast<const PyMesh&>().mesh;
  }
  if (faces.is_none()) throw InvalidInputError(function + "(V, F): F is missing");
  return mesh_from_python(first, faces);
}

std::shared_ptr<const Mesh> mesh_or_tree_argument(const std::string& function,
                                                  const py::object& first,
                                                  const py::object& faces) {
  if (!py::isinstance<PyHierarchy>(first)) return mesh_argument(function, first, faces);
  if (!faces.is_none()) throw InvalidInputError(function + "(hierarchy) takes no F");
  return first.cast<const PyHierarchy&>().hierarchy->shared_mesh();
}

double number_argument(const py::handle& value, const std::string& what) {
  if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value))
    throw InvalidInputError(what + " must be a number, not " + py::repr(value).cast<std::string>());
  try {
    return value.cast<double>();
  } catch (const py::cast_error&) {
    throw InvalidInputError(what + " must be a number, not " + py::repr(value).cast<std::string>());
  }
}

std::uint64_t unsigned_argument(const py::handle& value, const std::string& what,
                                std::uint64_t limit) {
  const std::string bad = what + " must be an integer in 0.." + std::to_string(limit) + ", not " +
                          py::repr(value).cast<std::string>();
  if (py::isinstance<py::bool_>(value) || !PyIndex_Check(value.ptr())) throw InvalidInputError(bad);
  const py::int_ integer = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
  if (!integer) throw py::error_already_set();
  const unsigned long long result = PyLong_AsUnsignedLongLong(integer.ptr());
  if (PyErr_Occurred()) {  // negative, or beyond 64 bits
    PyErr_Clear();
    throw InvalidInputError(bad);
  }
  if (result > limit) throw InvalidInputError(bad);
  return result;
}

py::array positions_array(std::vector<Vec3>&& positions) {
  const py::ssize_t rows = static_cast<py::ssize_t>(positions.size());
  return adopt<double>(std::move(positions), {rows, 3});
}

HierarchyOptions tool_hierarchy_options(const std::string& function, const PyHierarchy* given,
                                        const py::object& primitives, const py::object& weights,
                                        unsigned threads, unsigned regions,
                                        const py::object& default_primitives) {
  if (given) {
    if (!primitives.is_none() || !weights.is_none())
      throw InvalidInputError(function + "(hierarchy): primitives and weights are the hierarchy's");
    HierarchyOptions options = given->hierarchy->options();
    options.threads = threads;
    options.regions = regions;
    validate(options);
    return options;
  }
  if (!weights.is_none() && !py::isinstance<py::str>(weights))
    throw InvalidInputError("weights: must be 'area' or 'uniform', not " +
                            py::repr(weights).cast<std::string>());
  return hierarchy_options(primitives.is_none() ? default_primitives : primitives,
                           weights.is_none() ? std::string("area") : weights.cast<std::string>(),
                           threads, false, false, 0, regions);
}

}  // namespace primseg::python
