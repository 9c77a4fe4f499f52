// The `primseg` Python module: meshes from files or numpy arrays, the hierarchy, its levels, its
// clusters and its SciPy linkage matrix. Docstrings quote the C++ Doxygen text (generated header).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "../src/length_text.hpp"
#include "../src/parallel.hpp"
#include "../src/tree_nodes.hpp"
#include "doxygen_docstrings.hpp"
#include "primseg/auto_level.hpp"
#include "primseg/borders.hpp"
#include "primseg/cut.hpp"
#include "primseg/denoise.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_distance.hpp"
#include "primseg/mesh_info.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/primitives/primitive_fitter.hpp"
#include "primseg/refine.hpp"
#include "primseg/relations.hpp"
#include "primseg/render.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skeleton_gltf.hpp"
#include "primseg/skeleton_io.hpp"
#include "primseg/skinning.hpp"
#include "primseg/tree_io.hpp"

namespace py = pybind11;

namespace primseg::python {
namespace {

namespace doc = doxygen;

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

// "1 face", "2 faces" (for the reprs).
std::string count_of(std::uint64_t count, const std::string& noun, const std::string& plural = "") {
  return std::to_string(count) + " " + (count == 1 ? noun : plural.empty() ? noun + "s" : plural);
}

// ---------------------------------------------------------------------------------------------
// Arrays in: read in place with their own dtype and strides (no converted copy), checked with
// messages that name the array and the offending entry.

struct ArrayView {
  const char* data = nullptr;
  py::ssize_t rows = 0;
  py::ssize_t row_stride = 0, column_stride = 0;  // bytes
  char kind = 0;                                  // numpy dtype kind: 'f', 'i', 'u'
  py::ssize_t itemsize = 0;
};

// `object` as a numpy array: itself, or numpy.asarray of any other array-like.
py::array as_numpy_array(const py::handle& object) {
  if (py::isinstance<py::array>(object)) return py::reinterpret_borrow<py::array>(object);
  return py::array(py::module_::import("numpy").attr("asarray")(object));
}

// A numpy view of `object` (any array-like, see as_numpy_array), checked to be (n, 3) of an
// accepted kind and size. `owner` keeps the array alive.
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

template <typename T>
T element(const ArrayView& a, py::ssize_t row, py::ssize_t column) {
  T value;
  std::memcpy(&value, a.data + row * a.row_stride + column * a.column_stride, sizeof(T));
  return value;
}

std::string entry(const char* name, py::ssize_t row, py::ssize_t column) {
  return std::string(name) + "[" + std::to_string(row) + ", " + std::to_string(column) + "]";
}

template <typename T>
std::vector<Vec3> read_vertices(const ArrayView& a, const char* name = "V") {
  std::vector<Vec3> positions(static_cast<std::size_t>(a.rows));
  for (py::ssize_t i = 0; i < a.rows; ++i)
    for (py::ssize_t j = 0; j < 3; ++j) {
      const double value = static_cast<double>(element<T>(a, i, j));
      if (!std::isfinite(value))
        throw InvalidInputError(entry(name, i, j) + " is " + std::to_string(value) +
                                ": coordinates must be finite");
      positions[i][j] = value;
    }
  return positions;
}

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

std::shared_ptr<const Mesh> mesh_from_python(const py::handle& vertices, const py::handle& faces) {
  py::object v_owner, f_owner;
  const ArrayView v = view_n_by_3(vertices, "V", "float32 or float64", true, v_owner);
  const ArrayView f = view_n_by_3(faces, "F", "int32, int64, uint32 or uint64", false, f_owner);
  py::gil_scoped_release release;
  return std::make_shared<const Mesh>(mesh_from_arrays(v, f));
}

// ---------------------------------------------------------------------------------------------
// Arrays out: read-only views of the C++ storage, which their base object keeps alive.

py::array read_only(py::array array) {
  array.attr("flags").attr("writeable") = false;
  return array;
}

template <typename T>
py::array view(py::object owner, const void* data, std::vector<py::ssize_t> shape) {
  return read_only(py::array(py::dtype::of<T>(), std::move(shape), {}, data, std::move(owner)));
}

// A numpy array that owns a moved-in vector (no copy of the elements).
template <typename T, typename Source>
py::array adopt(std::vector<Source>&& values, std::vector<py::ssize_t> shape) {
  static_assert(sizeof(Source) % sizeof(T) == 0);
  auto* heap = new std::vector<Source>(std::move(values));
  py::capsule owner(heap, [](void* p) { delete static_cast<std::vector<Source>*>(p); });
  return py::array(py::dtype::of<T>(), std::move(shape), {}, heap->data(), owner);
}

// ---------------------------------------------------------------------------------------------
// The Python objects.

struct PyMesh {
  std::shared_ptr<const Mesh> mesh;
};

struct PyHierarchy {
  std::shared_ptr<const Hierarchy> hierarchy;
};

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
  for (const std::string& name : list) {
    const auto type = primitive_type_from_string(name);
    if (!type || !has_fitter(*type)) {
      std::string known;
      for (int t = 0; t < kPrimitiveTypeCount; ++t)
        if (has_fitter(static_cast<PrimitiveType>(t)))
          known += (known.empty() ? "'" : ", '") +
                   std::string(to_string(static_cast<PrimitiveType>(t))) + "'";
      throw InvalidInputError("primitives: unknown primitive '" + name + "' (available: " + known +
                              ")");
    }
    types.push_back(*type);
  }
  return types;
}

HierarchyOptions hierarchy_options(const py::object& primitives, const std::string& weights,
                                   unsigned threads, bool exact_costs, bool eager) {
  HierarchyOptions options;
  options.primitives = parse_primitives(primitives);
  if (weights != "area" && weights != "uniform")
    throw InvalidInputError("weights: must be 'area' or 'uniform', not '" + weights + "'");
  options.weights = weights == "uniform" ? VertexWeights::Uniform : VertexWeights::Area;
  options.threads = threads;
  options.exact_costs = exact_costs;
  options.evaluation = eager ? CandidateEvaluation::Eager : CandidateEvaluation::Lazy;
  validate(options);
  return options;
}

// Thrown from a build's progress callback to stop it once Python has an exception to raise: a
// signal's (Ctrl-C: KeyboardInterrupt) or the user's progress callable's. The Python error stays
// set, and the binding raises it once it holds the GIL again.
struct PythonErrorPending {};

// The progress callback of a hierarchy built without the GIL: it takes the GIL (about every
// percent of the merges) to let Python handle signals and to call `progress` (None, or a callable
// taking the fraction done): either can stop the build by raising, through PythonErrorPending.
// Made, and destroyed, while the GIL is held: it holds a reference to `progress`.
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

// Runs `work` without the GIL; a PythonErrorPending it throws (from python_progress) becomes the
// pending Python exception, raised once the GIL is held again.
template <class Work>
auto without_gil(Work&& work) {
  try {
    const py::gil_scoped_release release;
    return work();
  } catch (const PythonErrorPending&) {
    throw py::error_already_set();
  }
}

PyHierarchy segment_mesh(std::shared_ptr<const Mesh> mesh, const HierarchyOptions& options,
                         const py::object& progress) {
  const std::function<void(double)> report = python_progress(progress);
  return without_gil([&] {
    HierarchyBuilder builder(std::move(mesh), options);
    return PyHierarchy{std::make_shared<const Hierarchy>(builder.finish(report))};
  });
}

// The CLI's default level (--tolerance 0.1%): as a fraction of the bounding-box diagonal.
constexpr double kDefaultRelativeTolerance = 0.1 / 100;

// A level as Python gives it: k (a count or "auto"), tolerance or relative_tolerance.
using ClusterCount = std::optional<std::variant<std::int64_t, std::string>>;
struct LevelArguments {
  ClusterCount k;
  std::optional<double> tolerance, relative_tolerance;
};

// Throws InvalidInputError unless the level can be cut from a mesh of `face_count` faces:
// checked before any hierarchy is built.
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

// The segmentation of a level, as the CLI's --clusters K|auto and --tolerance T|T% cut it.
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

// The CLI's limit on --refine.
constexpr std::int64_t kMaxRefinePasses = 1000;
const char* kRefineArgument =
    R"(refine: up to this many passes of boundary refinement after the cut (the CLI's --refine N;
  0: none): border faces move to the adjacent cluster whose primitive fits them at least twice
  better, and the primitives are refitted. Raises InvalidInputError (a ValueError) outside
  0..1000.)";

const char* kRegularizeArgument =
    R"(regularize: make the fits' relations exact (the CLI's --regularize): plane normals and
  cylinder axes that agree within their uncertainty share one direction, cylinders one axis line
  (with the spheres centred on it), directions at right angles within it are made orthogonal,
  and cylinders and spheres of one radius share it; Hierarchy.relations() lists them.)";

const char* kRelationArguments =
    R"(relation_significance, max_relation_angle, max_radius_difference: the CLI's options of the
  same names (RelationOptions significance, max_angle_degrees, max_radius_difference): fits agree
  within relation_significance standard deviations (> 0), never beyond max_relation_angle degrees
  (in (0, 90)) or radii more than max_radius_difference apart (in (0, 1); a sphere's centre is
  put on an axis no farther than that fraction of its radius from it, and a cylinder made tangent
  to a plane or a parallel cylinder no farther than that fraction of its radius from tangent).
  relation_angle_tolerance (degrees, at least 0 and below max_relation_angle) and
  relation_length_tolerance (input units, >= 0, or a string "L%": L percent of the bounding-box
  diagonal, as the CLI's --relation-length-tolerance L%; RelationOptions angle_tolerance_degrees,
  length_tolerance): directions, and axis lines, offsets, centres, radii and tangency gaps, that
  agree within them are related whatever their uncertainty (for CAD parts, whose tessellation errs
  by more than the fits' statistics allow); 0, the default, leaves the significance alone. Raise
  InvalidInputError (a ValueError) outside these ranges.)";

// relation_length_tolerance as Python gives it: a length (input units), or "L%", L percent of the
// bounding-box diagonal.
using LengthArgument = std::variant<double, std::string>;

// The length of `argument` on `mesh`: a percentage by the CLI's parser (detail::parse_length, the
// same double); InvalidInputError, naming the keyword, for a string that is not one.
double length_argument(const LengthArgument& argument, const Mesh& mesh) {
  if (const double* length = std::get_if<double>(&argument)) return *length;
  const std::string& text = std::get<std::string>(argument);
  if (!detail::is_percentage(text))
    throw InvalidInputError("relation_length_tolerance is '" + text +
                            "', must be a non-negative length or a percentage of the "
                            "bounding-box diagonal such as '0.01%'");
  return detail::parse_length(text, bounding_box_diagonal(mesh), "relation_length_tolerance");
}

// The RelationOptions of relation_significance, max_relation_angle, relation_angle_tolerance,
// relation_length_tolerance and max_radius_difference for a level of `mesh`; InvalidInputError,
// naming the keyword, outside their ranges.
RelationOptions relation_arguments(const Mesh& mesh, double significance, double max_angle,
                                   double angle_tolerance, const LengthArgument& length,
                                   double max_difference) {
  auto refuse = [](const char* keyword, double value, const char* range) {
    throw InvalidInputError(std::string(keyword) + " is " + std::to_string(value) + ", must be " +
                            range);
  };
  const double length_tolerance = length_argument(length, mesh);
  if (!(significance > 0 && std::isfinite(significance)))
    refuse("relation_significance", significance, "a positive number");
  if (!(max_angle > 0 && max_angle < 90)) refuse("max_relation_angle", max_angle, "in (0, 90)");
  if (!(angle_tolerance >= 0 && angle_tolerance < max_angle))
    refuse("relation_angle_tolerance", angle_tolerance, "at least 0 and below max_relation_angle");
  if (!(length_tolerance >= 0 && std::isfinite(length_tolerance)))
    refuse("relation_length_tolerance", length_tolerance, "a finite number at least 0");
  if (!(max_difference > 0 && max_difference < 1))
    refuse("max_radius_difference", max_difference, "in (0, 1)");
  RelationOptions options;
  options.significance = significance;
  options.max_angle_degrees = max_angle;
  options.angle_tolerance_degrees = angle_tolerance;
  options.length_tolerance = length_tolerance;
  options.max_radius_difference = max_difference;
  return options;
}

// The level, refined by up to `refine` boundary passes (0: as cut), with its cluster reports when
// `reports` is given, and their relations made exact when `relations` is given too: what the
// CLI's --refine N and --regularize write.
Segmentation refined_level(const Hierarchy& hierarchy, const LevelArguments& level,
                           std::int64_t refine, std::vector<ClusterReport>* reports,
                           std::vector<ClusterRelation>* relations = nullptr,
                           const RelationOptions& relation_options = {}) {
  if (refine < 0 || refine > kMaxRefinePasses)
    throw InvalidInputError("refine must be a number of passes in [0, " +
                            std::to_string(kMaxRefinePasses) + "], not " + std::to_string(refine));
  Segmentation segmentation = cut_level(hierarchy, level);
  if (refine > 0) {
    BoundaryRefinementOptions options;
    options.max_passes = static_cast<std::uint32_t>(refine);
    RefinedLevel refined = refine_boundaries(hierarchy, segmentation, options);
    segmentation = std::move(refined.segmentation);
    if (reports) *reports = std::move(refined.reports);
  } else if (reports) {
    *reports = describe_clusters(hierarchy, segmentation);
  }
  if (reports && relations)
    *relations = regularize_clusters(hierarchy, segmentation, *reports, relation_options);
  return segmentation;
}

// The levels of `counts` clusters (each 1..F, in any order, repeats allowed), each with its
// clusters' reports and relations as refined_level() gives them with refine 0 and `relations`,
// bit for bit: one LevelRegularizer over the clusters of these levels alone (as the CLI's view
// --regularize), then the levels on `threads` threads (0: all cores), each computed once.
// Shape (counts.size()), in the order of `counts`.
std::vector<RegularizedLevel> regularized_levels(const Hierarchy& hierarchy,
                                                 const std::vector<std::uint32_t>& counts,
                                                 const RelationOptions& options, unsigned threads) {
  if (counts.empty()) return {};
  // The distinct levels, most clusters first: the costliest start first on the threads.
  std::vector<std::uint32_t> distinct = counts;
  std::sort(distinct.begin(), distinct.end(), std::greater<>());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  std::vector<std::uint32_t> nodes;
  for (const std::uint32_t clusters : distinct) {
    const std::vector<std::uint32_t> level = detail::level_nodes(hierarchy, clusters);
    nodes.insert(nodes.end(), level.begin(), level.end());
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  DescribeOptions describe;
  describe.threads = threads;
  const std::vector<ClusterReport> reports = describe_nodes(hierarchy, nodes, describe);
  const LevelRegularizer regularizer(hierarchy, nodes, reports, options, threads);
  std::vector<RegularizedLevel> levels(distinct.size());
  detail::parallel_for_threads(
      distinct.size(), detail::thread_count(threads),
      [&](std::size_t i, unsigned) { levels[i] = regularizer.level(distinct[i]); });
  std::vector<RegularizedLevel> ordered;
  ordered.reserve(counts.size());
  for (const std::uint32_t clusters : counts) {
    const auto at = std::lower_bound(distinct.begin(), distinct.end(), clusters, std::greater<>());
    ordered.push_back(levels[static_cast<std::size_t>(at - distinct.begin())]);
  }
  return ordered;
}

// write_mesh's `positions`: (n, 3) finite floats for the n vertices of `mesh`.
std::vector<Vec3> replacement_positions(const py::handle& object, const Mesh& mesh) {
  py::object owner;
  const ArrayView a = view_n_by_3(object, "positions", "float32 or float64", true, owner);
  if (static_cast<std::size_t>(a.rows) != mesh.vertex_count())
    throw InvalidInputError("positions has " + std::to_string(a.rows) + " rows for " +
                            std::to_string(mesh.vertex_count()) + " vertices");
  return a.itemsize == 4 ? read_vertices<float>(a, "positions")
                         : read_vertices<double>(a, "positions");
}

// write_mesh's `labels`: one non-negative integer per input face (polygon) of `mesh`.
std::vector<std::uint32_t> face_labels(const py::handle& object, const Mesh& mesh) {
  const py::array array = as_numpy_array(object);
  const char kind = array.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw InvalidInputError("labels must be an array of integers, not " +
                            py::repr(array.dtype().attr("name")).cast<std::string>());
  if (array.ndim() != 1 || static_cast<std::size_t>(array.shape(0)) != mesh.face_count())
    throw InvalidInputError("labels must have one entry per face: shape (" +
                            std::to_string(mesh.face_count()) + ",)");
  const py::array_t<std::int64_t> values(array.attr("astype")("int64"));
  std::vector<std::uint32_t> labels(mesh.face_count());
  for (std::size_t f = 0; f < labels.size(); ++f) {
    const std::int64_t label = values.at(static_cast<py::ssize_t>(f));
    if (label < 0 || label > std::numeric_limits<std::uint32_t>::max() - 1)
      throw InvalidInputError("labels[" + std::to_string(f) + "] = " + std::to_string(label) +
                              " is not a cluster id (0 .. 2^32 - 2)");
    labels[f] = static_cast<std::uint32_t>(label);
  }
  return labels;
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

// A border as the CLI's --json "borders" writes it.
// The CLI's JSON "relations": one dict {kind, clusters, deviation} per relation.
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

// ---------------------------------------------------------------------------------------------
// denoise, skeleton, distance: the CLI commands of those names.

// The mesh of a `mesh_or_V, F` argument pair: a Mesh (F must be None) or arrays V and F.
// `function` names the caller in messages.
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

// The first arguments of write_mesh and render: a Mesh, a Hierarchy (its mesh) or arrays V, F.
std::shared_ptr<const Mesh> mesh_or_tree_argument(const std::string& function,
                                                  const py::object& first,
                                                  const py::object& faces) {
  if (!py::isinstance<PyHierarchy>(first)) return mesh_argument(function, first, faces);
  if (!faces.is_none()) throw InvalidInputError(function + "(hierarchy) takes no F");
  return first.cast<const PyHierarchy&>().hierarchy->shared_mesh();
}

// One mesh of distance(a, b): a Mesh, a Hierarchy (its mesh) or a (V, F) pair.
std::shared_ptr<const Mesh> mesh_operand(const py::handle& operand, const char* name) {
  if (py::isinstance<PyMesh>(operand)) return operand.cast<const PyMesh&>().mesh;
  if (py::isinstance<PyHierarchy>(operand))
    return operand.cast<const PyHierarchy&>().hierarchy->shared_mesh();
  if ((py::isinstance<py::tuple>(operand) || py::isinstance<py::list>(operand)) &&
      py::len(operand) == 2) {
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(operand);
    return mesh_from_python(pair[0], pair[1]);
  }
  throw InvalidInputError(std::string(name) +
                          " must be a Mesh, a Hierarchy or a (V, F) pair, not " +
                          py::repr(py::type::of(operand)).cast<std::string>());
}

// A Python number as a double, or InvalidInputError naming `what`.
double number_argument(const py::handle& value, const std::string& what) {
  if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value))
    throw InvalidInputError(what + " must be a number, not " + py::repr(value).cast<std::string>());
  try {
    return value.cast<double>();
  } catch (const py::cast_error&) {
    throw InvalidInputError(what + " must be a number, not " + py::repr(value).cast<std::string>());
  }
}

// A Python integer in [0, limit], or InvalidInputError naming `what`.
std::uint64_t unsigned_argument(const py::handle& value, const std::string& what,
                                std::uint64_t limit = std::numeric_limits<std::uint64_t>::max()) {
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

// A pose: rotations as the CLI's pose file gives them ({"rotations": [...]}, or the list alone),
// each a dict {"joint": J, "axis": [x, y, z], "degrees": A} or a (joint, axis, degrees) tuple.
std::vector<JointRotation> pose_argument(const py::handle& pose) {
  py::object rotations = py::reinterpret_borrow<py::object>(pose);
  if (py::isinstance<py::dict>(pose)) {
    const py::dict file = py::reinterpret_borrow<py::dict>(pose);
    if (!file.contains("rotations"))
      throw InvalidInputError("pose: a dict must have \"rotations\" (as a pose file)");
    rotations = file["rotations"];
  }
  if (!py::isinstance<py::sequence>(rotations) || py::isinstance<py::str>(rotations))
    throw InvalidInputError("pose must be a list of rotations, not " +
                            py::repr(py::type::of(rotations)).cast<std::string>());
  std::vector<JointRotation> result;
  const py::sequence list = py::reinterpret_borrow<py::sequence>(rotations);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = "pose rotation " + std::to_string(i);
    py::object joint, axis, degrees;
    const py::object item = list[i];
    if (py::isinstance<py::dict>(item)) {
      const py::dict rotation = py::reinterpret_borrow<py::dict>(item);
      for (const char* key : {"joint", "axis", "degrees"})
        if (!rotation.contains(key)) throw InvalidInputError(where + ": missing \"" + key + "\"");
      joint = rotation["joint"], axis = rotation["axis"], degrees = rotation["degrees"];
    } else if (py::isinstance<py::sequence>(item) && !py::isinstance<py::str>(item) &&
               py::len(item) == 3) {
      const py::sequence triple = py::reinterpret_borrow<py::sequence>(item);
      joint = triple[0], axis = triple[1], degrees = triple[2];
    } else {
      throw InvalidInputError(where + " must be a dict {\"joint\", \"axis\", \"degrees\"} or a " +
                              "(joint, axis, degrees) tuple, not " +
                              py::repr(item).cast<std::string>());
    }
    JointRotation rotation;
    rotation.joint = static_cast<std::uint32_t>(
        unsigned_argument(joint, where + ": joint", std::numeric_limits<std::uint32_t>::max() - 1));
    if (!py::isinstance<py::sequence>(axis) || py::isinstance<py::str>(axis) || py::len(axis) != 3)
      throw InvalidInputError(where + ": axis must be 3 numbers");
    const py::sequence components = py::reinterpret_borrow<py::sequence>(axis);
    for (std::size_t c = 0; c < 3; ++c) {
      rotation.axis[c] = number_argument(components[c], where + ": axis");
      if (!std::isfinite(rotation.axis[c]))
        throw InvalidInputError(where + ": axis must be finite");
    }
    const double angle_degrees = number_argument(degrees, where + ": degrees");
    if (!std::isfinite(angle_degrees))
      throw InvalidInputError(where + ": degrees must be a finite number");
    rotation.angle = angle_degrees * (std::numbers::pi / 180);  // as the CLI's pose file
    result.push_back(rotation);
  }
  return result;
}

py::list index_list(const std::vector<std::uint32_t>& ids) {
  py::list list;
  for (const std::uint32_t id : ids) list.append(id);
  return list;
}

// The skeleton of a level, with the mesh it was made from and its skin weights once asked for.
struct PySkeleton {
  std::shared_ptr<const Mesh> mesh;
  std::shared_ptr<const Skeleton> skeleton;
  // The weights of the last band asked for: a pose then costs one pass over the vertices.
  std::shared_ptr<const SkinWeights> weights;
  double weights_band = 0;

  // Computed without the GIL; cached with it (the caller holds it when this returns).
  std::shared_ptr<const SkinWeights> skin_weights(double band) {
    if (!(std::isfinite(band) && band >= 0))
      throw InvalidInputError("band must be a finite number >= 0, not " + std::to_string(band));
    if (weights && weights_band == band) return weights;
    std::shared_ptr<const SkinWeights> computed;
    {
      py::gil_scoped_release release;
      SkinningOptions options;
      options.band = band;
      computed =
          std::make_shared<const SkinWeights>(compute_skin_weights(*mesh, *skeleton, options));
    }
    weights = computed;
    weights_band = band;
    return computed;
  }
};

// A skeleton read from a file or a pickle, for `mesh`: one label per face, or InvalidInputError.
PySkeleton skeleton_of_mesh(std::shared_ptr<const Mesh> mesh, Skeleton skeleton,
                            const std::string& name) {
  if (skeleton.face_labels.size() != mesh->face_count())
    throw InvalidInputError("'" + name + "' was made from a mesh of " +
                            std::to_string(skeleton.face_labels.size()) + " faces, this one has " +
                            std::to_string(mesh->face_count()));
  PySkeleton out;
  out.mesh = std::move(mesh);
  out.skeleton = std::make_shared<const Skeleton>(std::move(skeleton));
  return out;
}

// The joints and bones as the CLI's skeleton file lists them.
py::dict joint_dict(const Joint& joint) {
  py::dict dict;
  dict["id"] = joint.id;
  dict["position"] = vector_list(joint.position);
  dict["kind"] = std::string(to_string(joint.kind));
  dict["visible"] = joint.visible;
  dict["bones"] = index_list(joint.bones);
  return dict;
}

py::dict bone_dict(const Bone& bone) {
  py::dict dict;
  dict["id"] = bone.id;
  dict["cluster"] = bone.cluster;
  dict["joints"] = index_list(bone.joints);
  dict["visible"] = bone.visible;
  dict["axis"] = vector_list(bone.axis);
  dict["point"] = vector_list(bone.point);
  dict["radius"] = bone.radius;
  dict["area"] = bone.area;
  return dict;
}

py::list joint_list(const Skeleton& skeleton) {
  py::list list;
  for (const Joint& joint : skeleton.joints) list.append(joint_dict(joint));
  return list;
}

py::list bone_list(const Skeleton& skeleton) {
  py::list list;
  for (const Bone& bone : skeleton.bones) list.append(bone_dict(bone));
  return list;
}

py::array positions_array(std::vector<Vec3>&& positions) {
  const py::ssize_t rows = static_cast<py::ssize_t>(positions.size());
  return adopt<double>(std::move(positions), {rows, 3});
}

// One side of `primseg distance --json`: the figures in input units and in percent of the
// bounding-box diagonal, computed as the CLI computes them (the same doubles).
py::dict distance_side(const OneSidedDistance& d, double diagonal) {
  const double percent = diagonal > 0 ? 100 / diagonal : 0;
  py::dict side;
  side["mean"] = d.mean;
  side["rms"] = d.rms;
  side["max"] = d.max;
  side["samples"] = d.samples;
  side["mean_percent"] = d.mean * percent;
  side["rms_percent"] = d.rms * percent;
  side["max_percent"] = d.max * percent;
  return side;
}

py::dict snap_report_dict(const SnapReport& r) {
  py::dict round;
  round["clusters"] = r.clusters;
  round["boundary_vertices"] = r.boundary_vertices;
  round["snapped"] = r.snapped;
  round["moved"] = r.moved;
  round["fallbacks"] = r.fallbacks;
  round["blocked"] = r.blocked;
  round["mean_move"] = r.mean_move;
  round["max_move"] = r.max_move;
  return round;
}

// The hierarchy options of denoise and skeleton: those of a given Hierarchy (primitives and
// weights must then be None), else the arguments with `default_primitives`.
HierarchyOptions tool_hierarchy_options(const std::string& function, const PyHierarchy* given,
                                        const py::object& primitives, const py::object& weights,
                                        unsigned threads, const py::object& default_primitives) {
  if (given) {
    if (!primitives.is_none() || !weights.is_none())
      throw InvalidInputError(function + "(hierarchy): primitives and weights are the hierarchy's");
    HierarchyOptions options = given->hierarchy->options();
    options.threads = threads;
    return options;
  }
  if (!weights.is_none() && !py::isinstance<py::str>(weights))
    throw InvalidInputError("weights: must be 'area' or 'uniform', not " +
                            py::repr(weights).cast<std::string>());
  return hierarchy_options(primitives.is_none() ? default_primitives : primitives,
                           weights.is_none() ? std::string("area") : weights.cast<std::string>(),
                           threads, false, false);
}

// ---------------------------------------------------------------------------------------------
// Exceptions: primseg.Error (RuntimeError) and its subclasses, which are also the matching
// built-in kinds, so that `except OSError` or `except ValueError` catch them too.

py::object new_exception(py::module_& module, const char* name, const char* doc, py::tuple bases) {
  const std::string qualified = std::string("primseg.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), /*dict=*/nullptr);
  if (!type) throw py::error_already_set();
  py::object object = py::reinterpret_steal<py::object>(type);
  module.add_object(name, object);
  return object;
}

void register_exceptions(py::module_& m) {
  static py::object error, io_error, parse_error, invalid_input_error;
  const py::object builtins = py::module_::import("builtins");
  error =
      new_exception(m, "Error", doc::error__Error, py::make_tuple(builtins.attr("RuntimeError")));
  io_error = new_exception(m, "IoError", doc::error__IoError,
                           py::make_tuple(error, builtins.attr("OSError")));
  parse_error = new_exception(m, "ParseError", doc::error__ParseError, py::make_tuple(error));
  invalid_input_error =
      new_exception(m, "InvalidInputError",
                    (std::string(doc::error__InvalidInputError) +
                     "\nAlso raised for unusable numpy arrays (shape, dtype, NaN, indices).")
                        .c_str(),
                    py::make_tuple(error, builtins.attr("ValueError")));
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const IoError& e) {
      PyErr_SetString(io_error.ptr(), e.what());
    } catch (const ParseError& e) {
      PyErr_SetString(parse_error.ptr(), e.what());
    } catch (const InvalidInputError& e) {
      PyErr_SetString(invalid_input_error.ptr(), e.what());
    } catch (const Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });
}

const char* kLevelArguments =
    R"(Exactly one level, or none for the CLI's default (relative_tolerance=0.001, i.e.
`--tolerance 0.1%`):
  k: number of clusters, 1..F (below the number of connected components C you get C), or
    "auto": the most significant level of the error curve (the CLI's --clusters auto);
  tolerance: the coarsest level whose clusters each have an RMS distance estimate of at
    most `tolerance` to their primitive, input units;
  relative_tolerance: the same as a fraction of the bounding-box diagonal (0.001 = 0.1%).
Raises InvalidInputError (a ValueError) for k outside 1..F, a string other than "auto", or a
negative or NaN tolerance.)";

}  // namespace
}  // namespace primseg::python

PYBIND11_MODULE(primseg, m) {
  using namespace primseg;
  using namespace primseg::python;
  m.doc() = join_docs({doc::hierarchy__file, R"(Typical use:

    import primseg
    mesh = primseg.read_mesh("part.ply")          # or primseg.segment(V, F) from numpy arrays
    h = primseg.segment(mesh)                      # the whole tree, once (GIL released)
    labels = h.cut(12)                             # any level: int32 label per input face
    for c in h.clusters(12):                       # like the CLI's --json clusters
        print(c["type"], c["faces"], c["rms"], c["params"])
    Z = h.linkage()                                # scipy.cluster.hierarchy linkage matrix
    V2 = primseg.denoise(mesh, k=30)               # primseg denoise: new positions (n, 3)
    s = primseg.skeleton(mesh, k=12)               # primseg skeleton: joints, bones, deform(pose)
    d = primseg.distance(mesh, (V2, mesh.F))       # primseg distance --json, as a dict)"});
  m.attr("__version__") = "0.1.0";
  // Every docstring starts with its own Python signature (pybind11's would show C++ types).
  py::options docstring_options;
  docstring_options.disable_function_signatures();
  register_exceptions(m);

  // Registered before the functions that return it, so that their signatures name it.
  py::class_<PyHierarchy> hierarchy_class(
      m, "Hierarchy",
      join_docs({"The whole merge tree of a mesh (from segment or read_tree). Read-only; pickles "
                 "as its tree file's bytes (Hierarchy.save).",
                 cpp_doc("Hierarchy", doc::hierarchy__Hierarchy)})
          .c_str());

  py::class_<PyMesh>(m, "Mesh",
                     join_docs({"A polygon mesh and its triangulation (read-only; pickles).",
                                cpp_doc("Mesh", doc::mesh__Mesh)})
                         .c_str())
      .def(py::init([](const py::object& V, const py::object& F) {
             return PyMesh{mesh_from_python(V, F)};
           }),
           py::arg("V"), py::arg("F"),
           join_docs({R"(Mesh(V, F): a triangle mesh from numpy arrays.

V: (n, 3) float32 or float64 vertex positions; F: (m, 3) int32, int64, uint32 or uint64 vertex
indices; C- or Fortran-ordered or strided, read in place. Raises InvalidInputError (a
ValueError) for a wrong shape or dtype, a non-finite coordinate, an index out of range or no
faces.)",
                      cpp_doc("Mesh::from_triangles", doc::mesh__Mesh__from_triangles)})
               .c_str())
      .def_property_readonly(
          "V",
          [](const py::object& self) {
            const Mesh& mesh = *self.cast<const PyMesh&>().mesh;
            return view<double>(self, mesh.positions.data(), {mesh.vertex_count(), 3});
          },
          join_docs({"(n, 3) float64, read-only view (no copy).",
                     cpp_doc("Mesh::positions", doc::mesh__Mesh__positions)})
              .c_str())
      .def_property_readonly(
          "F",
          [](const py::object& self) {
            const Mesh& mesh = *self.cast<const PyMesh&>().mesh;
            return view<std::int32_t>(self, mesh.triangles.data(), {mesh.triangle_count(), 3});
          },
          join_docs({"(T, 3) int32 triangles, read-only view (no copy).",
                     cpp_doc("Mesh::triangles", doc::mesh__Mesh__triangles)})
              .c_str())
      .def_property_readonly(
          "face_of_triangle",
          [](const py::object& self) {
            const Mesh& mesh = *self.cast<const PyMesh&>().mesh;
            return view<std::int32_t>(self, mesh.face_of_triangle.data(), {mesh.triangle_count()});
          },
          join_docs({"(T,) int32: the input face (row of F, or polygon of the file) each triangle "
                     "came from; read-only view.",
                     cpp_doc("Mesh::face_of_triangle", doc::mesh__Mesh__face_of_triangle)})
              .c_str())
      .def_property_readonly(
          "face_count", [](const PyMesh& self) { return self.mesh->face_count(); },
          doc::mesh__Mesh__face_count)
      .def_property_readonly("vertex_count",
                             [](const PyMesh& self) { return self.mesh->vertex_count(); })
      .def_property_readonly("triangle_count",
                             [](const PyMesh& self) { return self.mesh->triangle_count(); })
      .def_property_readonly(
          "bounding_box_diagonal",
          [](const PyMesh& self) { return bounding_box_diagonal(*self.mesh); },
          doc::mesh__bounding_box_diagonal)
      .def(
          "info",
          [](const PyMesh& self) {
            MeshInfo i;
            std::optional<std::string> out_of_range;
            {
              py::gil_scoped_release release;
              i = describe_mesh(*self.mesh);
              try {
                check_geometric_range(*self.mesh);
              } catch (const InvalidInputError& error) {
                out_of_range = error.what();
              }
            }
            py::dict d;
            d["vertices"] = i.vertices;
            d["isolated_vertices"] = i.isolated_vertices;
            d["faces"] = i.faces;
            d["polygons"] = i.polygons;
            d["triangles"] = i.triangles;
            d["components"] = i.components;
            d["boundary_edges"] = i.boundary_edges;
            d["non_manifold_edges"] = i.non_manifold_edges;
            d["degenerate_triangles"] = i.degenerate_triangles;
            d["duplicate_triangles"] = i.duplicate_triangles;
            d["inconsistent_edges"] = i.inconsistent_edges;
            d["inward_components"] = i.inward_components;
            d["bbox_min"] = vector_list(i.bbox_min);
            d["bbox_max"] = vector_list(i.bbox_max);
            d["bbox_diagonal"] = i.bbox_diagonal;
            d["out_of_range"] = out_of_range ? py::object(py::str(*out_of_range)) : py::none();
            return d;
          },
          join_docs({R"(info() -> dict

What `primseg info` prints, as a dict: vertices, isolated_vertices, faces, polygons (faces of
more than 3 vertices), triangles, components, boundary_edges, non_manifold_edges,
degenerate_triangles, duplicate_triangles, inconsistent_edges (edges whose two triangles are
listed in the same direction along it), inward_components (closed components facing inwards),
bbox_min, bbox_max, bbox_diagonal, and
out_of_range: None, or the message the other functions would raise for coordinates too large
or too spread out to fit reliably.)",
                     cpp_doc("describe_mesh", doc::mesh_info__file),
                     cpp_doc("check_geometric_range", doc::mesh__check_geometric_range)})
              .c_str())
      .def("__repr__",
           [](const PyMesh& self) {
             return "<primseg.Mesh: " + count_of(self.mesh->vertex_count(), "vertex", "vertices") +
                    ", " + count_of(self.mesh->face_count(), "face") + ", " +
                    count_of(self.mesh->triangle_count(), "triangle") + ">";
           })
      // Read-only: a copy is the object itself.
      .def("__copy__", [](const py::object& self) { return self; })
      .def("__deepcopy__", [](const py::object& self, const py::dict&) { return self; })
      .def(py::pickle(&mesh_state, &mesh_from_state));

  m.def(
      "read_mesh",
      [](const std::filesystem::path& path) {
        py::gil_scoped_release release;
        return PyMesh{std::make_shared<const Mesh>(read_mesh(path))};
      },
      py::arg("path"),
      join_docs({R"(read_mesh(path) -> Mesh

Raises IoError (an OSError) when the file cannot be read, ParseError (a RuntimeError) when it is
malformed, InvalidInputError (a ValueError) for an unknown extension, NaN coordinates or no
faces.)",
                 cpp_doc("read_mesh", doc::mesh_io__read_mesh)})
          .c_str());

  m.def(
      "write_mesh",
      [](const std::filesystem::path& path, const py::object& first, const py::object& faces,
         const py::object& positions, const py::object& labels, bool binary) {
        std::shared_ptr<const Mesh> mesh = mesh_or_tree_argument("write_mesh", first, faces);
        Mesh moved;
        if (!positions.is_none()) {
          moved = *mesh;
          moved.positions = replacement_positions(positions, *mesh);
        }
        const std::vector<std::uint32_t> groups =
            labels.is_none() ? std::vector<std::uint32_t>{} : face_labels(labels, *mesh);
        MeshWriteOptions options;
        options.face_groups = groups;
        options.binary = binary;
        py::gil_scoped_release release;
        write_mesh(path, positions.is_none() ? *mesh : moved, options);
      },
      py::arg("path"), py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(),
      py::arg("positions") = py::none(), py::arg("labels") = py::none(), py::arg("binary") = true,
      join_docs(
          {R"(write_mesh(path, mesh, *, positions=None, labels=None, binary=True)
write_mesh(path, V, F, *, ...)

Writes a Mesh (its input polygons), a Hierarchy's mesh, or arrays V (n, 3) and F (m, 3), in the
format of the extension (.off .obj .ply .stl), through a temporary file renamed into place.
positions: (n, 3) float new positions of the same vertices (what denoise() and
Skeleton.deform() return), written with the mesh's faces: the CLI's denoise and deform outputs.
labels: one non-negative integer per face (per input polygon, like cut()'s), written as face
colours (PLY, OFF) or groups (OBJ), like the CLI's --colored; STL has neither.
binary: PLY and STL binary (little-endian) or ASCII.
Raises InvalidInputError (a ValueError) for an unknown extension or bad arrays, IoError (an
OSError) when the file cannot be written.)",
           cpp_doc("write_mesh", doc::mesh_io__write_mesh),
           cpp_doc("MeshWriteOptions::face_groups", doc::mesh_io__MeshWriteOptions__face_groups)})
          .c_str());

  m.def(
      "render",
      [](const py::object& first, const py::object& faces, const py::object& labels, int width,
         int height, const std::array<double, 3>& view, const std::array<double, 3>& up, bool edges,
         bool borders, const std::optional<std::filesystem::path>& path) {
        const std::shared_ptr<const Mesh> mesh = mesh_or_tree_argument("render", first, faces);
        const std::vector<std::uint32_t> groups =
            labels.is_none() ? std::vector<std::uint32_t>{} : face_labels(labels, *mesh);
        RenderOptions options;
        options.width = width;
        options.height = height;
        options.view_direction = view;
        options.up = up;
        options.edges = edges;
        options.borders = borders;
        std::vector<std::uint8_t> rgb;
        {
          py::gil_scoped_release release;
          rgb = render_mesh(*mesh, group_face_colors(groups), options);
          if (path) write_png(*path, rgb, width, height);
        }
        return adopt<std::uint8_t>(std::move(rgb), {height, width, 3});
      },
      py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(),
      py::arg("labels") = py::none(), py::arg("width") = 800, py::arg("height") = 600,
      py::arg("view") = std::array<double, 3>{-1.0, -0.8, -1.3},
      py::arg("up") = std::array<double, 3>{0.0, 1.0, 0.0}, py::arg("edges") = false,
      py::arg("borders") = false, py::arg("path") = py::none(),
      join_docs(
          {R"(render(mesh, *, labels=None, width=800, height=600, view=(-1, -0.8, -1.3), up=(0, 1, 0), edges=False, borders=False, path=None) -> numpy.ndarray
render(V, F, *, ...) -> numpy.ndarray

A picture of a Mesh, a Hierarchy's mesh or arrays V, F: uint8 (height, width, 3), top row first
(matplotlib: plt.imshow(picture)). labels: one integer per face (cut()'s), each cluster in the
colour of the CLI's --png and --colored; None: light grey. view: direction from the eye to the
model; up: direction that points up in the picture; edges: draw the triangle edges; borders:
draw only the lines between clusters and along the open boundary. path: also write the picture
there as PNG (the CLI's --png, byte for byte, with cut()'s labels and borders=True).
Raises InvalidInputError (a ValueError) for sizes outside 1..16384 or bad arrays, IoError (an
OSError) when the PNG cannot be written.)",
           cpp_doc("render_mesh", doc::render__render_mesh),
           cpp_doc("RenderOptions", doc::render__RenderOptions),
           cpp_doc("group_face_colors", doc::mesh_io__group_face_colors)})
          .c_str());

  const char* segment_doc =
      R"(segment(mesh, *, primitives=("plane", "cylinder", "sphere"), weights="area", threads=0, exact_costs=False, eager=False, progress=None) -> Hierarchy
segment(V, F, *, ...) -> Hierarchy

Builds the whole hierarchy, with the GIL released. About every percent of the merges it takes the
GIL back for a moment: Ctrl-C (KeyboardInterrupt) stops the build there, and progress, if given,
is called with the fraction done (0 to 1; a progress bar); an exception it raises stops the
build and propagates. The input is a Mesh (read_mesh: labels are per input polygon, like the
CLI's) or arrays V (n, 3) float32/float64 and F (m, 3) int32/int64/uint32/uint64, C- or
Fortran-ordered, read in place without a converted copy (labels are per row of F).
primitives: names or one name ("plane", "cylinder", "sphere"); weights: "area" or "uniform";
threads: 0 for all cores (the tree does not depend on it); exact_costs: slow reference mode;
eager: evaluate every candidate at once (reference mode, the same tree).
Raises InvalidInputError (a ValueError) for bad arrays (shape, dtype, NaN or infinite
coordinates, index out of range, no faces) or bad options.)";
  m.def(
      "segment",
      [](const py::object& first, const py::object& faces, const py::object& primitives,
         const std::string& weights, unsigned threads, bool exact_costs, bool eager,
         const py::object& progress) {
        const HierarchyOptions options =
            hierarchy_options(primitives, weights, threads, exact_costs, eager);
        return segment_mesh(mesh_argument("segment", first, faces), options, progress);
      },
      py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(),
      py::arg("primitives") = py::make_tuple("plane", "cylinder", "sphere"),
      py::arg("weights") = "area", py::arg("threads") = 0u, py::arg("exact_costs") = false,
      py::arg("eager") = false, py::arg("progress") = py::none(),
      join_docs(
          {segment_doc, cpp_doc("build_hierarchy", doc::hierarchy__build_hierarchy_2),
           cpp_doc("HierarchyOptions::primitives", doc::hierarchy__HierarchyOptions__primitives),
           cpp_doc("HierarchyOptions::weights", doc::hierarchy__HierarchyOptions__weights),
           cpp_doc("HierarchyOptions::threads", doc::hierarchy__HierarchyOptions__threads),
           cpp_doc("HierarchyOptions::evaluation", doc::hierarchy__HierarchyOptions__evaluation),
           cpp_doc("HierarchyOptions::exact_costs", doc::hierarchy__HierarchyOptions__exact_costs)})
          .c_str());

  m.def(
      "read_skeleton",
      [](const std::filesystem::path& path, const py::object& first, const py::object& faces) {
        const std::shared_ptr<const Mesh> mesh =
            mesh_or_tree_argument("read_skeleton", first, faces);
        Skeleton skeleton;
        {
          py::gil_scoped_release release;
          skeleton = read_skeleton(path);
        }
        return skeleton_of_mesh(mesh, std::move(skeleton), path.string());
      },
      py::arg("path"), py::arg("mesh_or_V"), py::arg("F") = py::none(),
      join_docs({R"(read_skeleton(path, mesh) -> Skeleton
read_skeleton(path, V, F) -> Skeleton

A skeleton file (`primseg skeleton -o`, Skeleton.save) with the mesh it was made from (a Mesh, a
Hierarchy's or arrays V and F): the Skeleton primseg.skeleton() gave, for deform(), gltf() and
skin_weights() without building the hierarchy again. Raises ParseError for a malformed file,
InvalidInputError when its face labels do not fit the mesh.)",
                 cpp_doc("parse_skeleton_json", doc::skeleton_io__parse_skeleton_json)})
          .c_str());

  m.def(
      "read_tree",
      [](const std::filesystem::path& path) {
        py::gil_scoped_release release;
        return PyHierarchy{std::make_shared<const Hierarchy>(read_tree(path))};
      },
      py::arg("path"),
      join_docs({"read_tree(path) -> Hierarchy: a tree file written by Hierarchy.save or the "
                 "CLI's --tree.",
                 cpp_doc("read_tree", doc::tree_io__read_tree)})
          .c_str());

  hierarchy_class
      .def(
          "cut",
          [](const PyHierarchy& self, ClusterCount k, std::optional<double> tolerance,
             std::optional<double> relative_tolerance, std::int64_t refine) {
            const LevelArguments level{std::move(k), tolerance, relative_tolerance};
            Segmentation segmentation;
            {
              py::gil_scoped_release release;
              segmentation = refined_level(*self.hierarchy, level, refine, nullptr);
            }
            const py::ssize_t faces = static_cast<py::ssize_t>(segmentation.labels.size());
            return adopt<std::int32_t>(std::move(segmentation.labels), {faces});
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(), py::arg("refine") = 0,
          join_docs(
              {R"(cut(k=None, *, tolerance=None, relative_tolerance=None, refine=0) -> numpy.ndarray

The cluster of each input face, int32 (F,), values 0..K-1 numbered by decreasing area: the same
labels as the CLI's --labels.)",
               kLevelArguments, kRefineArgument, cpp_doc("cut_by_count", doc::cut__cut_by_count),
               cpp_doc("cut_by_tolerance", doc::cut__cut_by_tolerance),
               cpp_doc("refine_boundaries", doc::refine__refine_boundaries)})
              .c_str())
      .def(
          "clusters",
          [](const PyHierarchy& self, ClusterCount k, std::optional<double> tolerance,
             std::optional<double> relative_tolerance, std::int64_t refine, bool regularize,
             double significance, double max_angle, double angle_tolerance,
             const LengthArgument& length_tolerance, double max_difference) {
            const LevelArguments level{std::move(k), tolerance, relative_tolerance};
            std::vector<ClusterReport> reports;
            {
              py::gil_scoped_release release;
              std::vector<ClusterRelation> relations;
              refined_level(*self.hierarchy, level, refine, &reports,
                            regularize ? &relations : nullptr,
                            relation_arguments(self.hierarchy->mesh(), significance, max_angle,
                                               angle_tolerance, length_tolerance, max_difference));
            }
            py::list clusters;
            for (const ClusterReport& report : reports) clusters.append(cluster_dict(report));
            return clusters;
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(), py::arg("refine") = 0,
          py::arg("regularize") = false,
          py::arg("relation_significance") = RelationOptions{}.significance,
          py::arg("max_relation_angle") = RelationOptions{}.max_angle_degrees,
          py::arg("relation_angle_tolerance") = RelationOptions{}.angle_tolerance_degrees,
          py::arg("relation_length_tolerance") = RelationOptions{}.length_tolerance,
          py::arg("max_radius_difference") = RelationOptions{}.max_radius_difference,
          join_docs(
              {R"(clusters(k=None, *, tolerance=None, relative_tolerance=None, refine=0, regularize=False, relation_significance=3.0, max_relation_angle=20.0, relation_angle_tolerance=0.0, relation_length_tolerance=0.0, max_radius_difference=0.05) -> list of dict

One dict per cluster, in label order, with the keys and values of the CLI's --json "clusters":
id, type ("plane", "cylinder", "sphere"), faces (count), area, rms, max, and params (input
units: plane {normal, point}, sphere {center, radius}, cylinder {axis, point, radius}; vectors
as lists). json.dumps() takes it as it is.)",
               kLevelArguments, kRefineArgument, kRegularizeArgument, kRelationArguments,
               cpp_doc("ClusterReport", doc::cut__ClusterReport),
               cpp_doc("ClusterReport::rms", doc::cut__ClusterReport__rms),
               cpp_doc("ClusterReport::max", doc::cut__ClusterReport__max),
               cpp_doc("named_parameters", doc::primitive__named_parameters)})
              .c_str())
      .def(
          "borders",
          [](const PyHierarchy& self, ClusterCount k, std::optional<double> tolerance,
             std::optional<double> relative_tolerance, std::int64_t refine, bool regularize,
             double significance, double max_angle, double angle_tolerance,
             const LengthArgument& length_tolerance, double max_difference) {
            const LevelArguments level{std::move(k), tolerance, relative_tolerance};
            std::vector<ClusterBorder> borders;
            {
              py::gil_scoped_release release;
              std::vector<ClusterReport> reports;
              std::vector<ClusterRelation> relations;
              const Segmentation segmentation = refined_level(
                  *self.hierarchy, level, refine, &reports, regularize ? &relations : nullptr,
                  relation_arguments(self.hierarchy->mesh(), significance, max_angle,
                                     angle_tolerance, length_tolerance, max_difference));
              borders = cluster_borders(self.hierarchy->mesh(), segmentation.labels,
                                        cluster_primitives(reports));
            }
            py::list list;
            for (const ClusterBorder& border : borders) list.append(border_dict(border));
            return list;
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(), py::arg("refine") = 0,
          py::arg("regularize") = false,
          py::arg("relation_significance") = RelationOptions{}.significance,
          py::arg("max_relation_angle") = RelationOptions{}.max_angle_degrees,
          py::arg("relation_angle_tolerance") = RelationOptions{}.angle_tolerance_degrees,
          py::arg("relation_length_tolerance") = RelationOptions{}.length_tolerance,
          py::arg("max_radius_difference") = RelationOptions{}.max_radius_difference,
          join_docs(
              {R"(borders(k=None, *, tolerance=None, relative_tolerance=None, refine=0, regularize=False, relation_significance=3.0, max_relation_angle=20.0, relation_angle_tolerance=0.0, relation_length_tolerance=0.0, max_radius_difference=0.05) -> list of dict

Where the clusters of the level meet, as the CLI's --json "borders": one dict per border with
clusters (a, b), b None along the mesh's open boundary; edges (count); length (input units);
angle (degrees between the two fitted surfaces across it: 0 tangent, 90 a box's edge; None on
the open boundary); and curves, a list of dicts {closed, vertices} with the vertex indices in
order along each curve. json.dumps() takes it as it is.)",
               kLevelArguments, kRefineArgument, kRegularizeArgument, kRelationArguments,
               cpp_doc("cluster_borders", doc::borders__cluster_borders),
               cpp_doc("ClusterBorder::angle", doc::borders__ClusterBorder__angle),
               cpp_doc("ClusterBorder::curves", doc::borders__ClusterBorder__curves)})
              .c_str())
      .def(
          "relations",
          [](const PyHierarchy& self, ClusterCount k, std::optional<double> tolerance,
             std::optional<double> relative_tolerance, std::int64_t refine, double significance,
             double max_angle, double angle_tolerance, const LengthArgument& length_tolerance,
             double max_difference) {
            const LevelArguments level{std::move(k), tolerance, relative_tolerance};
            std::vector<ClusterRelation> relations;
            {
              py::gil_scoped_release release;
              std::vector<ClusterReport> reports;
              refined_level(*self.hierarchy, level, refine, &reports, &relations,
                            relation_arguments(self.hierarchy->mesh(), significance, max_angle,
                                               angle_tolerance, length_tolerance, max_difference));
            }
            return relations_list(relations);
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(), py::arg("refine") = 0,
          py::arg("relation_significance") = RelationOptions{}.significance,
          py::arg("max_relation_angle") = RelationOptions{}.max_angle_degrees,
          py::arg("relation_angle_tolerance") = RelationOptions{}.angle_tolerance_degrees,
          py::arg("relation_length_tolerance") = RelationOptions{}.length_tolerance,
          py::arg("max_radius_difference") = RelationOptions{}.max_radius_difference,
          join_docs(
              {R"(relations(k=None, *, tolerance=None, relative_tolerance=None, refine=0, relation_significance=3.0, max_relation_angle=20.0, relation_angle_tolerance=0.0, relation_length_tolerance=0.0, max_radius_difference=0.05) -> list of dict

The design intent among the level's fits, as the CLI's --regularize writes it in the JSON's
"relations": one dict per relation with kind ("parallel": plane normals and cylinder axes of one
direction; "coaxial": cylinders of one axis line and spheres centred on it, or three spheres or
more centred on one line with no cylinder; "orthogonal": two directions at right angles;
"equal_radius": cylinders and spheres of one radius; "coplanar": planes of one plane, the
fragments of one face; "tangent": a cylinder and a plane it borders, the cylinder tangent to it,
as a fillet and the face it rounds, or two parallel cylinders that border each other, as a fillet
and the boss it rounds) and clusters (their labels, increasing; for
"orthogonal", those of one direction, and orthogonal_to those of the other), and deviation: how
far the clusters' own fits were from the relation (degrees for "parallel" and "orthogonal", input
units otherwise), what a tolerance must reach for it to hold whatever the statistics.
clusters(..., regularize=True) gives the primitives with these relations made exact.)",
               kLevelArguments, kRefineArgument, kRelationArguments,
               cpp_doc("regularize_clusters", doc::relations__regularize_clusters),
               cpp_doc("relations.hpp", doc::relations__file)})
              .c_str())
      .def(
          "relations_of_levels",
          [](const PyHierarchy& self, const std::vector<std::int64_t>& ks, double significance,
             double max_angle, double angle_tolerance, const LengthArgument& length_tolerance,
             double max_difference, unsigned threads) {
            const RelationOptions options =
                relation_arguments(self.hierarchy->mesh(), significance, max_angle, angle_tolerance,
                                   length_tolerance, max_difference);
            std::vector<std::uint32_t> counts;
            counts.reserve(ks.size());
            for (std::size_t i = 0; i < ks.size(); ++i) {
              try {
                validate_level({ks[i], std::nullopt, std::nullopt}, self.hierarchy->face_count());
              } catch (const InvalidInputError& error) {
                throw InvalidInputError("ks[" + std::to_string(i) + "]: " + error.what());
              }
              counts.push_back(static_cast<std::uint32_t>(ks[i]));
            }
            std::vector<RegularizedLevel> levels;
            {
              py::gil_scoped_release release;
              levels = regularized_levels(*self.hierarchy, counts, options, threads);
            }
            py::list list;
            for (std::size_t i = 0; i < levels.size(); ++i) {
              py::list clusters;
              for (const ClusterReport& report : levels[i].reports)
                clusters.append(cluster_dict(report));
              py::dict level;
              level["k"] = ks[i];
              level["clusters"] = clusters;
              level["relations"] = relations_list(levels[i].relations);
              list.append(level);
            }
            return list;
          },
          py::arg("ks"), py::kw_only(),
          py::arg("relation_significance") = RelationOptions{}.significance,
          py::arg("max_relation_angle") = RelationOptions{}.max_angle_degrees,
          py::arg("relation_angle_tolerance") = RelationOptions{}.angle_tolerance_degrees,
          py::arg("relation_length_tolerance") = RelationOptions{}.length_tolerance,
          py::arg("max_radius_difference") = RelationOptions{}.max_radius_difference,
          py::arg("threads") = 0u,
          join_docs(
              {R"(relations_of_levels(ks, *, relation_significance=3.0, max_relation_angle=20.0, relation_angle_tolerance=0.0, relation_length_tolerance=0.0, max_radius_difference=0.05, threads=0) -> list of dict

The relations and the regularized fits of many levels at once: one dict per entry of ks (numbers
of clusters, in their order; repeats allowed) with k (the entry), clusters (the list
clusters(k, regularize=True) gives) and relations (the list relations(k) gives), equal to those
calls' results bit for bit. Each of those calls gathers the vertices of every cluster from all F
faces; this gathers those of the clusters of the levels asked for once, so that a level then
costs its relations alone (as the CLI's view --regularize browses them level by level): for
levels 1..100, a fraction of the time of the calls one by one. ks = [] gives []. Raises
InvalidInputError (a ValueError) naming the entry, "ks[i]: k must be between 1 and the number
of faces (F), not ...", and TypeError for an entry that is not an integer.)",
               kRelationArguments,
               R"(threads: 0 for all cores (the results do not depend on it); the levels, the fits
  of their clusters and the gathering of their vertices run on them.)",
               cpp_doc("LevelRegularizer", doc::relations__LevelRegularizer),
               cpp_doc("LevelRegularizer::level", doc::relations__LevelRegularizer__level)})
              .c_str())
      .def(
          "auto_level",
          [](const PyHierarchy& self) {
            AutoLevel level;
            {
              py::gil_scoped_release release;
              level = choose_level(*self.hierarchy);
            }
            py::list candidates;
            for (const LevelCandidate& c : level.candidates) {
              py::dict candidate;
              candidate["clusters"] = c.clusters;
              candidate["rms"] = c.rms;
              candidate["score"] = c.score;
              candidates.append(candidate);
            }
            py::dict d;
            d["clusters"] = level.clusters;
            d["rule"] = std::string(to_string(level.rule));
            d["candidates"] = candidates;
            return d;
          },
          join_docs({R"(auto_level() -> dict

The level cut("auto") takes and why, as the CLI's --json "level" reports it: clusters (K), rule
("jump", "knee" or "components") and candidates (best score first: dicts of clusters, rms in
input units, and score).)",
                     cpp_doc("choose_level", doc::auto_level__choose_level),
                     cpp_doc("AutoLevel::clusters", doc::auto_level__AutoLevel__clusters),
                     cpp_doc("LevelCandidate::score", doc::auto_level__LevelCandidate__score)})
              .c_str())
      .def(
          "error_curve",
          [](const PyHierarchy& self) {
            std::vector<ErrorCurvePoint> points;
            {
              py::gil_scoped_release release;
              points = error_curve(*self.hierarchy);
            }
            std::vector<std::array<double, 2>> rows(points.size());
            for (std::size_t i = 0; i < points.size(); ++i)
              rows[i] = {static_cast<double>(points[i].clusters), points[i].rms};
            const py::ssize_t count = static_cast<py::ssize_t>(rows.size());
            return adopt<double>(std::move(rows), {count, 2});
          },
          join_docs({R"(error_curve() -> numpy.ndarray

The RMS distance estimate of every level, float64 (F - C + 1, 2): rows (K, rms) for K from the
number of components C to F, in input units; the CLI's --curve CSV. To plot and choose a level
by eye: plt.semilogy(*curve.T).)",
                     cpp_doc("error_curve", doc::auto_level__error_curve),
                     cpp_doc("ErrorCurvePoint::rms", doc::auto_level__ErrorCurvePoint__rms)})
              .c_str())
      .def(
          "linkage",
          [](const PyHierarchy& self) {
            std::vector<std::array<double, 4>> rows = scipy_linkage(*self.hierarchy);
            const py::ssize_t count = static_cast<py::ssize_t>(rows.size());
            return adopt<double>(std::move(rows), {count, 4});
          },
          join_docs({R"(linkage() -> numpy.ndarray

The whole tree as SciPy's (F - 1, 4) float64 linkage matrix (children ids, height, size), for
scipy.cluster.hierarchy: cut_tree(Z, n_clusters=k) and fcluster(Z, k, "maxclust") give the
same clusters as cut(k). The same matrix as the CLI's --linkage.)",
                     cpp_doc("scipy_linkage", doc::cut__scipy_linkage),
                     cpp_doc("Merge::cost", doc::hierarchy__Merge__cost)})
              .c_str())
      .def(
          "merges",
          [](const PyHierarchy& self) {
            const Hierarchy& tree = *self.hierarchy;
            const std::span<const Merge> merges = tree.merges();
            const std::size_t n = merges.size();
            const auto rows = static_cast<py::ssize_t>(n);
            std::vector<std::array<std::int32_t, 2>> children(n);
            std::vector<std::int32_t> face_count(n);
            std::vector<std::uint8_t> trailing(n);
            std::vector<std::int8_t> type(n);
            std::vector<Vec3> point(n), axis(n);
            std::vector<double> rms(n), radius(n), minor_radius(n), half_angle(n);
            for (std::size_t i = 0; i < n; ++i) {
              const Merge& merge = merges[i];
              children[i] = {static_cast<std::int32_t>(merge.first),
                             static_cast<std::int32_t>(merge.second)};
              face_count[i] = static_cast<std::int32_t>(merge.face_count);
              trailing[i] = merge.trailing ? 1 : 0;
              type[i] = merge.trailing ? -1 : static_cast<std::int8_t>(merge.primitive.type);
              rms[i] = merge.trailing
                           ? std::numeric_limits<double>::quiet_NaN()
                           : tree.rms_estimate(tree.face_count() + static_cast<std::uint32_t>(i));
              point[i] = merge.primitive.point;
              axis[i] = merge.primitive.axis;
              radius[i] = merge.primitive.radius;
              minor_radius[i] = merge.primitive.minor_radius;
              half_angle[i] = merge.primitive.half_angle;
            }
            // Type names by code, "" for the trailing merges (code -1, the last entry).
            py::list names;
            for (int t = 0; t < kPrimitiveTypeCount; ++t)
              names.append(std::string(to_string(static_cast<PrimitiveType>(t))));
            names.append("");
            const py::module_ numpy = py::module_::import("numpy");
            py::dict table;
            table["children"] = adopt<std::int32_t>(std::move(children), {rows, 2});
            table["face_count"] = adopt<std::int32_t>(std::move(face_count), {rows});
            table["trailing"] = adopt<bool>(std::move(trailing), {rows});  // bytes 0 and 1
            table["type"] = numpy.attr("array")(names).attr("__getitem__")(
                adopt<std::int8_t>(std::move(type), {rows}));
            table["rms"] = adopt<double>(std::move(rms), {rows});
            table["point"] = adopt<double>(std::move(point), {rows, 3});
            table["axis"] = adopt<double>(std::move(axis), {rows, 3});
            table["radius"] = adopt<double>(std::move(radius), {rows});
            table["minor_radius"] = adopt<double>(std::move(minor_radius), {rows});
            table["half_angle"] = adopt<double>(std::move(half_angle), {rows});
            return table;
          },
          join_docs({R"(merges() -> dict

Every merge of the tree, one row per node it makes (row i is node F + i; nodes 0..F-1 are the
faces), as numpy arrays of length F - 1: children (F - 1, 2) int32 (node ids, as linkage()),
face_count int32, trailing bool (merges joining connected components after all real ones: no
fit), and the primitive the greedy fitted to the node from its moments: type str ("plane",
"cylinder", "sphere", "cone", "torus"; "" when trailing), rms float64 (the node's RMS distance
estimate, input units; NaN when trailing), point and axis (F - 1, 3) float64, radius,
minor_radius and half_angle float64 (radians), in input units, zero where the type has none.
Hierarchy.clusters() refits a level's clusters geometrically and measures their exact errors;
these are the tree's own fits, for rules of one's own over all nodes.)",
                     cpp_doc("Merge", doc::hierarchy__Merge),
                     cpp_doc("Hierarchy::rms_estimate", doc::hierarchy__Hierarchy__rms_estimate)})
              .c_str())
      .def(
          "save",
          [](const PyHierarchy& self, const std::filesystem::path& path) {
            py::gil_scoped_release release;
            write_tree(path, *self.hierarchy);
          },
          py::arg("path"),
          join_docs({"save(path): the tree file (read_tree, or the CLI's `primseg cut`).",
                     cpp_doc("write_tree", doc::tree_io__write_tree)})
              .c_str())
      .def_property_readonly(
          "mesh", [](const PyHierarchy& self) { return PyMesh{self.hierarchy->shared_mesh()}; },
          "The mesh the tree was built on (shared, no copy).")
      .def_property_readonly(
          "face_count", [](const PyHierarchy& self) { return self.hierarchy->face_count(); },
          "F, the number of input faces: the length of every label array.")
      .def_property_readonly(
          "component_count",
          [](const PyHierarchy& self) { return self.hierarchy->component_count(); },
          "Connected components: the fewest clusters any cut gives.")
      .def_property_readonly(
          "primitives",
          [](const PyHierarchy& self) {
            py::tuple names(self.hierarchy->options().primitives.size());
            for (std::size_t i = 0; i < names.size(); ++i)
              names[i] = std::string(to_string(self.hierarchy->options().primitives[i]));
            return names;
          },
          doc::hierarchy__HierarchyOptions__primitives)
      .def_property_readonly(
          "weights",
          [](const PyHierarchy& self) {
            return self.hierarchy->options().weights == VertexWeights::Uniform ? "uniform" : "area";
          },
          doc::hierarchy__HierarchyOptions__weights)
      .def("__repr__",
           [](const PyHierarchy& self) {
             return "<primseg.Hierarchy: " + count_of(self.hierarchy->face_count(), "face") + ", " +
                    count_of(self.hierarchy->component_count(), "component") + ">";
           })
      .def("__copy__", [](const py::object& self) { return self; })
      .def("__deepcopy__", [](const py::object& self, const py::dict&) { return self; })
      // Pickled as its tree file (Hierarchy.save's bytes): for multiprocessing and joblib.
      .def(py::pickle(
          [](const PyHierarchy& self) {
            std::string bytes;
            {
              py::gil_scoped_release release;
              bytes = serialize_tree(*self.hierarchy);
            }
            return py::make_tuple(py::bytes(bytes));
          },
          [](const py::tuple& state) {
            if (state.size() != 1 || !py::isinstance<py::bytes>(state[0]))
              throw InvalidInputError("Hierarchy: not a pickled primseg.Hierarchy");
            // The bytes object outlives the read (the caller holds the state): no copy.
            const auto bytes = state[0].cast<std::string_view>();
            py::gil_scoped_release release;
            return PyHierarchy{std::make_shared<const Hierarchy>(
                deserialize_tree(bytes, "pickled primseg.Hierarchy"))};
          }));

  // ------------------------------------------------------------------------------------------
  // denoise, skeleton, distance.

  const char* denoise_doc =
      R"(denoise(mesh, *, k=None, tolerance=None, relative_tolerance=None, iterations=1, smoothing_steps=0, bilateral=False, stylize=False, max_move=4.0, min_crease_angle=10.0, relabel_passes=2, relation_significance=3.0, noise_tolerance_factor=None, primitives=None, weights=None, threads=0, return_rounds=False, return_level=False, progress=None) -> numpy.ndarray
denoise(V, F, *, ...) -> numpy.ndarray
denoise(hierarchy, *, ...) -> numpy.ndarray

`primseg denoise`: snaps every vertex onto the primitives of a level, `iterations` times (each
round segments the previous round's result), and returns the new positions, float64 (n, 3), in
the input's vertex order (the faces do not change): the CLI's output mesh, bit for bit. With
return_rounds=True it returns (V, rounds), rounds a list of dicts like the CLI's --json
"denoise" "rounds" (clusters, boundary_vertices, snapped, moved, fallbacks, blocked, mean_move,
max_move). With return_level=True it returns (V, level), or (V, rounds, level) with both: the
last round's snap (Denoiser::snapped_level) as a dict of "labels" (int32 (F,), the CLI's
--labels), "clusters", "borders" and "relations" (the CLI's --json entries: the clusters after
relabelling with the primitives the vertices went onto, their borders on the denoised mesh, and
the groups of clusters made parallel or coaxial, {kind, clusters}).
The input is a Mesh, arrays V and F (as segment takes them), or a Hierarchy: its first round
then snaps onto that tree's level without building it again (smoothing_steps must be 0, and the
later rounds use its primitives and weights).
Level: k (count or "auto"), tolerance or relative_tolerance as in Hierarchy.cut, the CLI's
--clusters and --tolerance; none: 0.1% of the diagonal. k="auto" is denoising's automatic level
(Denoiser::automatic_level): a jump of the error curve whose clusters each fit within 4.5
times that tolerance, else the clusters within a multiple of the estimated noise
(noise_tolerance_factor: None for the default of the segmented copy).
stylize: --stylize (each vertex onto its own cluster's primitive); max_move: --max-move (in mean
incident edge lengths); min_crease_angle: --min-crease-angle (degrees); relabel_passes:
--relabel-passes (faces moved to the nearest refitted neighbouring primitive);
relation_significance: --relation-significance (0: no parallel or coaxial relations); smoothing_steps:
--smooth (Taubin steps on the copy that is segmented); bilateral: --bilateral (that copy
smoothed by bilateral normal filtering instead, which keeps edges sharp); primitives (default plane, cylinder, sphere) and weights (default "area"): as in
segment. The GIL is released while it works; as in segment, Ctrl-C (KeyboardInterrupt) stops a
round's hierarchy build, and progress, if given, is called during the builds with the fraction
of all rounds done (0 to 1).
Raises InvalidInputError (a ValueError) for bad arrays or options out of range.)";
  m.def(
      "denoise",
      [](const py::object& first, const py::object& faces, ClusterCount k,
         std::optional<double> tolerance, std::optional<double> relative_tolerance, int iterations,
         int smoothing_steps, bool bilateral, bool stylize, double max_move,
         double min_crease_angle, int relabel_passes, double relation_significance,
         std::optional<double> noise_tolerance_factor, const py::object& primitives,
         const py::object& weights, unsigned threads, bool return_rounds, bool return_level,
         const py::object& progress) -> py::object {
        const LevelArguments level{std::move(k), tolerance, relative_tolerance};
        const PyHierarchy* given =
            py::isinstance<PyHierarchy>(first) ? &first.cast<const PyHierarchy&>() : nullptr;
        if (given && !faces.is_none())
          throw InvalidInputError("denoise(hierarchy) takes no F (give the level as k=...)");
        if (relabel_passes < 0 || relabel_passes > 100)
          throw InvalidInputError(
              "relabel_passes must be between 0 and 100 (the CLI's range), not " +
              std::to_string(relabel_passes));
        DenoiseOptions options;
        options.mode = stylize ? SnapMode::NearestIncident : SnapMode::AllIncident;
        options.max_move_edge_lengths = max_move;
        options.min_crease_angle_degrees = min_crease_angle;
        options.relabel_passes = relabel_passes;
        options.relation_significance = relation_significance;
        options.noise_tolerance_factor = noise_tolerance_factor;
        options.smoothing_steps = smoothing_steps;
        if (bilateral) options.bilateral_smoothing = BilateralSmoothingOptions{};
        options.hierarchy = tool_hierarchy_options("denoise", given, primitives, weights, threads,
                                                   py::make_tuple("plane", "cylinder", "sphere"));
        validate(options);
        if (iterations < 1 || iterations > 100)
          throw InvalidInputError("iterations must be between 1 and 100 (the CLI's range), not " +
                                  std::to_string(iterations));
        if (smoothing_steps < 0 || smoothing_steps > 1000)
          throw InvalidInputError(
              "smoothing_steps must be between 0 and 1000 (the CLI's range), not " +
              std::to_string(smoothing_steps));
        if (given && (smoothing_steps > 0 || bilateral))
          throw InvalidInputError(
              "denoise(hierarchy): smoothing_steps must be 0 and bilateral False (the tree was "
              "built on the mesh as it is); give the mesh to segment a smoothed copy");
        const std::shared_ptr<const Mesh> mesh =
            given ? given->hierarchy->shared_mesh() : mesh_argument("denoise", first, faces);
        validate_level(level, mesh->face_count());
        const std::function<void(double)> progress_of_all = python_progress(progress);
        std::vector<SnapReport> reports;
        std::vector<Vec3> positions;
        SnappedLevel snapped;
        std::vector<ClusterBorder> borders;
        without_gil([&] {
          Denoiser denoiser(*mesh, options);
          // k="auto": denoising's own automatic level, as `primseg denoise --clusters auto`.
          const bool automatic = level.k && std::holds_alternative<std::string>(*level.k);
          for (int round = 0; round < iterations; ++round) {
            // As `primseg denoise`: each round segments the previous round's result.
            const auto report_round = [&](double fraction) {
              progress_of_all((round + fraction) / iterations);
            };
            const std::shared_ptr<const Hierarchy> hierarchy =
                round == 0 && given
                    ? given->hierarchy
                    : std::make_shared<const Hierarchy>(
                          HierarchyBuilder(denoiser.segmented_mesh(), options.hierarchy)
                              .finish(report_round));
            reports.push_back(denoiser.snap(
                *hierarchy, automatic ? denoiser.automatic_level(*hierarchy).segmentation
                                      : cut_level(*hierarchy, level)));
          }
          if (return_level) {
            snapped = denoiser.snapped_level();
            borders = cluster_borders(denoiser.mesh(), snapped.labels,
                                      cluster_primitives(snapped.clusters));
          }
          positions = denoiser.mesh().positions;
        });
        py::array V = positions_array(std::move(positions));
        if (!return_rounds && !return_level) return V;
        py::list result;
        result.append(V);
        if (return_rounds) {
          py::list rounds;
          for (const SnapReport& report : reports) rounds.append(snap_report_dict(report));
          result.append(rounds);
        }
        if (return_level) {
          py::dict snapped_dict;
          py::list clusters, border_list;
          for (const ClusterReport& report : snapped.clusters)
            clusters.append(cluster_dict(report));
          for (const ClusterBorder& border : borders) border_list.append(border_dict(border));
          const auto face_count = static_cast<py::ssize_t>(snapped.labels.size());
          snapped_dict["labels"] = adopt<std::int32_t>(std::move(snapped.labels), {face_count});
          snapped_dict["clusters"] = clusters;
          snapped_dict["borders"] = border_list;
          snapped_dict["relations"] = relations_list(snapped.relations);
          result.append(snapped_dict);
        }
        return py::tuple(result);
      },
      py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(), py::arg("k") = py::none(),
      py::arg("tolerance") = py::none(), py::arg("relative_tolerance") = py::none(),
      py::arg("iterations") = 1, py::arg("smoothing_steps") = DenoiseOptions{}.smoothing_steps,
      py::arg("bilateral") = false, py::arg("stylize") = false,
      py::arg("max_move") = DenoiseOptions{}.max_move_edge_lengths,
      py::arg("min_crease_angle") = DenoiseOptions{}.min_crease_angle_degrees,
      py::arg("relabel_passes") = DenoiseOptions{}.relabel_passes,
      py::arg("relation_significance") = DenoiseOptions{}.relation_significance,
      py::arg("noise_tolerance_factor") = py::none(), py::arg("primitives") = py::none(),
      py::arg("weights") = py::none(), py::arg("threads") = 0u, py::arg("return_rounds") = false,
      py::arg("return_level") = false, py::arg("progress") = py::none(),
      join_docs(
          {denoise_doc, cpp_doc("denoise.hpp", doc::denoise__file),
           cpp_doc("DenoiseOptions::max_move_edge_lengths",
                   doc::denoise__DenoiseOptions__max_move_edge_lengths),
           cpp_doc("DenoiseOptions::min_crease_angle_degrees",
                   doc::denoise__DenoiseOptions__min_crease_angle_degrees),
           cpp_doc("DenoiseOptions::relabel_passes", doc::denoise__DenoiseOptions__relabel_passes),
           cpp_doc("DenoiseOptions::relation_significance",
                   doc::denoise__DenoiseOptions__relation_significance),
           cpp_doc("DenoiseOptions::noise_tolerance_factor",
                   doc::denoise__DenoiseOptions__noise_tolerance_factor),
           cpp_doc("DenoiseOptions::smoothing_steps",
                   doc::denoise__DenoiseOptions__smoothing_steps),
           cpp_doc("DenoiseOptions::bilateral_smoothing",
                   doc::denoise__DenoiseOptions__bilateral_smoothing),
           cpp_doc("SnapMode", doc::denoise__SnapMode),
           cpp_doc("SnapReport", doc::denoise__SnapReport),
           cpp_doc("SnappedLevel", doc::denoise__SnappedLevel)})
          .c_str());

  py::class_<PySkeleton>(
      m, "Skeleton",
      join_docs({R"(A deformation skeleton (from primseg.skeleton): one bone per cluster of a level,
joints where clusters meet, the mesh it was made from, its skin weights and poses.

joints and bones are lists of dicts with the keys and values of the CLI's skeleton file;
to_dict() is that file without its "mesh", "primitives", "requested_clusters" and "timing".)",
                 cpp_doc("Skeleton", doc::skeleton__Skeleton),
                 cpp_doc("extract_skeleton", doc::skeleton__extract_skeleton)})
          .c_str())
      .def_property_readonly(
          "joints", [](const PySkeleton& self) { return joint_list(*self.skeleton); },
          R"(List of dicts: id, position [x, y, z] (input units), kind ("sensitive", "locked" or
"virtual"), visible, bones (incident bone ids).)")
      .def_property_readonly(
          "bones", [](const PySkeleton& self) { return bone_list(*self.skeleton); },
          R"(List of dicts, bone i is cluster i: id, cluster, joints, visible, axis (unit), point,
radius, area (input units).)")
      .def_property_readonly(
          "joint_positions",
          [](const PySkeleton& self) {
            std::vector<Vec3> positions;
            for (const Joint& joint : self.skeleton->joints) positions.push_back(joint.position);
            return positions_array(std::move(positions));
          },
          "(J, 3) float64: the rest positions of the joints.")
      .def_property_readonly(
          "face_labels",
          [](const PySkeleton& self) {
            std::vector<std::uint32_t> labels = self.skeleton->face_labels;
            const py::ssize_t faces = static_cast<py::ssize_t>(labels.size());
            return adopt<std::int32_t>(std::move(labels), {faces});
          },
          doc::skeleton__Skeleton__face_labels)
      .def_property_readonly(
          "cluster_count", [](const PySkeleton& self) { return self.skeleton->cluster_count(); },
          "K, the number of bones (one per cluster).")
      .def_property_readonly(
          "root_bone", [](const PySkeleton& self) { return self.skeleton->root_bone(); },
          doc::skeleton__Skeleton__root_bone)
      .def_property_readonly(
          "mesh", [](const PySkeleton& self) { return PyMesh{self.mesh}; },
          "The mesh the skeleton was made from (shared, no copy).")
      .def(
          "save",
          [](const PySkeleton& self, const std::filesystem::path& path) {
            py::gil_scoped_release release;
            write_skeleton(path, *self.skeleton);
          },
          py::arg("path"),
          join_docs({"save(path): writes the skeleton file (JSON), as `primseg skeleton -o` does "
                     "without its summary; read_skeleton() and `primseg deform` read it.",
                     cpp_doc("write_skeleton", doc::skeleton_io__write_skeleton)})
              .c_str())
      // Read-only (the weights it caches are a function of the band): a copy is the object itself.
      .def("__copy__", [](const py::object& self) { return self; })
      .def("__deepcopy__", [](const py::object& self, const py::dict&) { return self; })
      .def(py::pickle(
          [](const PySkeleton& self) {
            return py::make_tuple(mesh_state(PyMesh{self.mesh}),
                                  py::bytes(skeleton_json(*self.skeleton)));
          },
          [](const py::tuple& state) {
            if (state.size() != 2 || !py::isinstance<py::tuple>(state[0]) ||
                !py::isinstance<py::bytes>(state[1]))
              throw InvalidInputError("Skeleton: not a pickled primseg.Skeleton");
            const std::string_view text = state[1].cast<std::string_view>();
            return skeleton_of_mesh(mesh_from_state(state[0].cast<py::tuple>()).mesh,
                                    parse_skeleton_json(text, "pickled primseg.Skeleton"),
                                    "pickled primseg.Skeleton");
          }))
      .def(
          "to_dict",
          [](const PySkeleton& self) {
            py::dict dict;
            dict["cluster_count"] = self.skeleton->cluster_count();
            dict["root_bone"] = self.skeleton->root_bone();
            dict["joints"] = joint_list(*self.skeleton);
            dict["bones"] = bone_list(*self.skeleton);
            dict["face_labels"] = index_list(self.skeleton->face_labels);
            return dict;
          },
          R"(to_dict() -> dict

cluster_count, root_bone, joints, bones and face_labels (a list): the CLI's skeleton file
(`primseg skeleton -o`) without its summary entries; json.dumps() takes it as it is.)")
      .def(
          "skin_weights",
          [](PySkeleton& self, double band, bool sparse) -> py::object {
            const std::shared_ptr<const SkinWeights> weights = self.skin_weights(band);
            const py::ssize_t n = weights->vertex_count();
            if (sparse) {
              std::vector<double> values = weights->weights;
              std::vector<std::uint32_t> bones = weights->bones, offsets = weights->offsets;
              const py::ssize_t entries = static_cast<py::ssize_t>(values.size());
              return py::make_tuple(adopt<double>(std::move(values), {entries}),
                                    adopt<std::int32_t>(std::move(bones), {entries}),
                                    adopt<std::int32_t>(std::move(offsets), {n + 1}));
            }
            const py::ssize_t k = self.skeleton->cluster_count();
            py::array_t<double> dense({n, k});
            double* out = dense.mutable_data();
            std::fill(out, out + n * k, 0.0);
            for (std::uint32_t v = 0; v < weights->vertex_count(); ++v) {
              const auto bones = weights->bones_of(v);
              const auto values = weights->weights_of(v);
              for (std::size_t i = 0; i < bones.size(); ++i) out[v * k + bones[i]] = values[i];
            }
            return dense;
          },
          py::arg("band") = SkinningOptions{}.band, py::arg("sparse") = false,
          join_docs({R"(skin_weights(band=0.5, sparse=False) -> numpy.ndarray or tuple

The weight of each bone for each vertex: float64 (n, K), rows summing to 1 (an unused vertex:
a row of zeros). sparse=True gives the compressed rows instead, (data float64, indices int32,
indptr int32), for scipy.sparse.csr_matrix((data, indices, indptr), shape=(n, K)): the CLI's
--skin-weights file. band: the CLI's --band (blend half-width in bone radii). Computed once per
band and kept for deform().)",
                     cpp_doc("skinning.hpp", doc::skinning__file),
                     cpp_doc("SkinningOptions::band", doc::skinning__SkinningOptions__band)})
              .c_str())
      .def(
          "deform",
          [](PySkeleton& self, const py::object& pose, double band) {
            const std::vector<JointRotation> rotations = pose_argument(pose);
            const std::shared_ptr<const SkinWeights> weights = self.skin_weights(band);
            std::vector<Vec3> positions;
            {
              py::gil_scoped_release release;
              const std::vector<RigidTransform> bones = pose_bones(*self.skeleton, rotations);
              positions = skin_positions(self.mesh->positions, *weights, bones);
            }
            return positions_array(std::move(positions));
          },
          py::arg("pose"), py::arg("band") = SkinningOptions{}.band,
          join_docs({R"(deform(pose, band=0.5) -> numpy.ndarray

`primseg deform`: the vertex positions, float64 (n, 3), of the mesh posed by rotating joints,
by linear blend skinning; the CLI's output mesh, bit for bit. pose: the CLI's pose file as
json.load gives it ({"rotations": [...]}), or its list of rotations, each a dict {"joint": J,
"axis": [x, y, z], "degrees": A} or a tuple (J, axis, degrees). Rotated joints must be
sensitive. Raises InvalidInputError (a ValueError) for a malformed pose, an unknown, locked or
repeated joint, or a zero axis.)",
                     cpp_doc("JointRotation", doc::skinning__JointRotation),
                     cpp_doc("pose_bones", doc::skinning__pose_bones),
                     cpp_doc("skin_positions", doc::skinning__skin_positions)})
              .c_str())
      .def(
          "gltf",
          [](PySkeleton& self, double band, std::int64_t max_influences) {
            if (max_influences < 0 || max_influences > std::numeric_limits<std::uint32_t>::max())
              throw InvalidInputError("max_influences must be >= 0 (0: all), not " +
                                      std::to_string(max_influences));
            const std::shared_ptr<const SkinWeights> weights = self.skin_weights(band);
            std::string bytes;
            {
              py::gil_scoped_release release;
              GltfOptions options;
              options.max_influences = static_cast<std::uint32_t>(max_influences);
              bytes = skinned_glb(*self.mesh, *self.skeleton, *weights, options);
            }
            return py::bytes(bytes);
          },
          py::arg("band") = SkinningOptions{}.band,
          py::arg("max_influences") = GltfOptions{}.max_influences,
          join_docs({R"(gltf(band=0.5, max_influences=0) -> bytes

`primseg skeleton --gltf`: the mesh skinned to this skeleton as a binary glTF 2.0 file (GLB), the
CLI's file byte for byte; write it with open(path, "wb").write(...) and open it in Blender,
three.js or a game engine. Rotating bone b's node (named "bone_b"; its extras name the joint it
turns about) poses the mesh as deform() does. band: as in skin_weights(); max_influences: as
the CLI's --max-influences (0 keeps every weight).)",
                     cpp_doc("skeleton_gltf.hpp", doc::skeleton_gltf__file),
                     cpp_doc("skinned_glb", doc::skeleton_gltf__skinned_glb)})
              .c_str())
      .def(
          "posed_joint_positions",
          [](const PySkeleton& self, const py::object& pose) {
            const std::vector<JointRotation> rotations = pose_argument(pose);
            return positions_array(
                posed_joint_positions(*self.skeleton, pose_bones(*self.skeleton, rotations)));
          },
          py::arg("pose"),
          join_docs({"posed_joint_positions(pose) -> numpy.ndarray: (J, 3) float64, the joints "
                     "in a pose (as deform takes it).",
                     cpp_doc("posed_joint_positions", doc::skinning__posed_joint_positions)})
              .c_str())
      .def(
          "bones_beyond",
          [](const PySkeleton& self, std::int64_t joint) {
            if (joint < 0 || joint >= static_cast<std::int64_t>(self.skeleton->joints.size()))
              throw InvalidInputError("joint must be between 0 and " +
                                      std::to_string(self.skeleton->joints.size()) + " - 1, not " +
                                      std::to_string(joint));
            return index_list(bones_beyond(*self.skeleton, static_cast<std::uint32_t>(joint)));
          },
          py::arg("joint"),
          join_docs({"bones_beyond(joint) -> list: the bones a rotation of `joint` moves.",
                     cpp_doc("bones_beyond", doc::skinning__bones_beyond)})
              .c_str())
      .def("__repr__", [](const PySkeleton& self) {
        return "<primseg.Skeleton: " + count_of(self.skeleton->cluster_count(), "bone") + ", " +
               count_of(self.skeleton->joints.size(), "joint") + ">";
      });

  m.def(
      "skeleton",
      [](const py::object& first, const py::object& faces, ClusterCount k,
         std::optional<double> tolerance, std::optional<double> relative_tolerance,
         const py::object& primitives, const py::object& weights, unsigned threads,
         const py::object& progress) {
        const LevelArguments level{std::move(k), tolerance, relative_tolerance};
        const PyHierarchy* given =
            py::isinstance<PyHierarchy>(first) ? &first.cast<const PyHierarchy&>() : nullptr;
        if (given && !faces.is_none())
          throw InvalidInputError("skeleton(hierarchy) takes no F (give the level as k=...)");
        const HierarchyOptions options = tool_hierarchy_options(
            "skeleton", given, primitives, weights, threads, py::make_tuple("cylinder"));
        const std::shared_ptr<const Mesh> mesh =
            given ? given->hierarchy->shared_mesh() : mesh_argument("skeleton", first, faces);
        validate_level(level, mesh->face_count());
        const std::function<void(double)> report = python_progress(progress);
        return without_gil([&] {
          const std::shared_ptr<const Hierarchy> hierarchy =
              given ? given->hierarchy
                    : std::make_shared<const Hierarchy>(
                          HierarchyBuilder(mesh, options).finish(report));
          PySkeleton skeleton;
          skeleton.mesh = mesh;
          skeleton.skeleton = std::make_shared<const Skeleton>(
              extract_skeleton(*hierarchy, cut_level(*hierarchy, level)));
          return skeleton;
        });
      },
      py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(), py::arg("k") = py::none(),
      py::arg("tolerance") = py::none(), py::arg("relative_tolerance") = py::none(),
      py::arg("primitives") = py::none(), py::arg("weights") = py::none(), py::arg("threads") = 0u,
      py::arg("progress") = py::none(),
      join_docs(
          {R"(skeleton(mesh, *, k=None, tolerance=None, relative_tolerance=None, primitives=None, weights=None, threads=0, progress=None) -> Skeleton
skeleton(V, F, *, ...) -> Skeleton
skeleton(hierarchy, *, ...) -> Skeleton

`primseg skeleton`: the deformation skeleton of a level, one bone per cluster. The input is a
Mesh, arrays V and F, or a Hierarchy (its tree, not built again). Level: k (count or "auto"),
tolerance or relative_tolerance as in Hierarchy.cut (the CLI asks for --clusters K|auto).
primitives: cylinders only by default, as the CLI (and the paper) do; weights: "area" by
default. The GIL is released while it works; Ctrl-C (KeyboardInterrupt) stops the hierarchy's
build, and progress, if given, is called during it with the fraction done, as in segment.)",
           cpp_doc("skeleton.hpp", doc::skeleton__file)})
          .c_str());

  m.def(
      "distance",
      [](const py::object& a, const py::object& b, const py::object& samples,
         std::optional<double> density, const py::object& seed, unsigned threads) {
        DistanceOptions options;
        if (!samples.is_none() && density)
          throw InvalidInputError("give samples or density, not both");
        if (!samples.is_none()) options.samples = unsigned_argument(samples, "samples");
        if (density) options.density = *density;
        options.seed = unsigned_argument(seed, "seed");
        options.threads = threads;
        const std::shared_ptr<const Mesh> first = mesh_operand(a, "a");
        const std::shared_ptr<const Mesh> second = mesh_operand(b, "b");
        MeshDistance d;
        {
          py::gil_scoped_release release;
          d = mesh_distance(*first, *second, options);
        }
        py::dict result;
        result["bbox_diagonal"] = d.diagonal;
        result["a_to_b"] = distance_side(d.a_to_b, d.diagonal);
        result["b_to_a"] = distance_side(d.b_to_a, d.diagonal);
        result["symmetric"] = distance_side(
            {d.mean, d.rms, d.hausdorff, d.a_to_b.samples + d.b_to_a.samples}, d.diagonal);
        result["seed"] = options.seed;
        return result;
      },
      py::arg("a"), py::arg("b"), py::kw_only(), py::arg("samples") = py::none(),
      py::arg("density") = py::none(), py::arg("seed") = DistanceOptions{}.seed,
      py::arg("threads") = 0u,
      join_docs({R"(distance(a, b, *, samples=None, density=None, seed=1, threads=0) -> dict

`primseg distance --json`: Metro-style distances between two surfaces, each a Mesh, a Hierarchy
(its mesh) or a (V, F) pair. Returns the CLI's JSON without its file names and timing:
bbox_diagonal, seed, and a_to_b, b_to_a, symmetric, each {mean, rms, max, samples,
mean_percent, rms_percent, max_percent} (input units, and percent of the diagonal of both
meshes' bounding box); symmetric "max" is the Hausdorff distance.
samples: area-uniform samples on each surface (default 200000); density: samples per unit area
instead; seed: of the sample positions (the same seed gives the same figures); threads: 0 for all
cores (the figures do not depend on it). The GIL is released while it works.)",
                 cpp_doc("mesh_distance", doc::mesh_distance__mesh_distance),
                 cpp_doc("OneSidedDistance", doc::mesh_distance__OneSidedDistance),
                 cpp_doc("OneSidedDistance::max", doc::mesh_distance__OneSidedDistance__max),
                 cpp_doc("MeshDistance::mean", doc::mesh_distance__MeshDistance__mean),
                 cpp_doc("DistanceOptions::density", doc::mesh_distance__DistanceOptions__density)})
          .c_str());
}
