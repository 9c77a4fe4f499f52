// The `primseg` Python module: meshes from files or numpy arrays, the hierarchy, its levels, its
// clusters and its SciPy linkage matrix. Docstrings quote the C++ Doxygen text (generated header).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "doxygen_docstrings.hpp"
#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/primitives/primitive_fitter.hpp"
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

// A numpy view of `object` (any array-like; a non-array is converted by numpy.asarray), checked
// to be (n, 3) of an accepted kind and size. `owner` keeps the array alive.
ArrayView view_n_by_3(const py::handle& object, const char* name, const char* accepted,
                      bool floating, py::object& owner) {
  const py::module_ numpy = py::module_::import("numpy");
  py::array array = py::isinstance<py::array>(object) ? py::reinterpret_borrow<py::array>(object)
                                                      : py::array(numpy.attr("asarray")(object));
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
std::vector<Vec3> read_vertices(const ArrayView& a) {
  std::vector<Vec3> positions(static_cast<std::size_t>(a.rows));
  for (py::ssize_t i = 0; i < a.rows; ++i)
    for (py::ssize_t j = 0; j < 3; ++j) {
      const double value = static_cast<double>(element<T>(a, i, j));
      if (!std::isfinite(value))
        throw InvalidInputError(entry("V", i, j) + " is " + std::to_string(value) +
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

PyHierarchy segment_mesh(std::shared_ptr<const Mesh> mesh, const HierarchyOptions& options) {
  py::gil_scoped_release release;
  return {std::make_shared<const Hierarchy>(build_hierarchy(std::move(mesh), options))};
}

// The CLI's default level (--tolerance 0.1%): as a fraction of the bounding-box diagonal.
constexpr double kDefaultRelativeTolerance = 0.1 / 100;

Segmentation cut_level(const Hierarchy& hierarchy, const std::optional<std::int64_t>& clusters,
                       const std::optional<double>& tolerance,
                       const std::optional<double>& relative_tolerance) {
  if (int(clusters.has_value()) + int(tolerance.has_value()) + int(relative_tolerance.has_value()) >
      1)
    throw InvalidInputError("give at most one of k, tolerance and relative_tolerance");
  if (clusters) {
    if (*clusters < 1 || *clusters > hierarchy.face_count())
      throw InvalidInputError("k must be between 1 and the number of faces (" +
                              std::to_string(hierarchy.face_count()) + "), not " +
                              std::to_string(*clusters));
    return cut_by_count(hierarchy, static_cast<std::uint32_t>(*clusters));
  }
  if (tolerance) return cut_by_tolerance(hierarchy, *tolerance);
  const double fraction = relative_tolerance.value_or(kDefaultRelativeTolerance);
  if (!std::isfinite(fraction) || fraction < 0)
    throw InvalidInputError("relative_tolerance must be a non-negative number, not " +
                            std::to_string(fraction));
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
  k: number of clusters, 1..F (below the number of connected components C you get C);
  tolerance: the coarsest level whose clusters each have an RMS distance estimate of at
    most `tolerance` to their primitive, input units;
  relative_tolerance: the same as a fraction of the bounding-box diagonal (0.001 = 0.1%).
Raises InvalidInputError (a ValueError) for k outside 1..F or a negative or NaN tolerance.)";

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

denoise, skeleton and distance will mirror the CLI commands once those exist.)"});
  m.attr("__version__") = "0.1.0";
  // Every docstring starts with its own Python signature (pybind11's would show C++ types).
  py::options docstring_options;
  docstring_options.disable_function_signatures();
  register_exceptions(m);

  // Registered before the functions that return it, so that their signatures name it.
  py::class_<PyHierarchy> hierarchy_class(
      m, "Hierarchy",
      join_docs({"The whole merge tree of a mesh (from segment or read_tree).",
                 cpp_doc("Hierarchy", doc::hierarchy__Hierarchy)})
          .c_str());

  py::class_<PyMesh>(m, "Mesh",
                     join_docs({"A polygon mesh and its triangulation (read-only).",
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
      .def("__repr__", [](const PyMesh& self) {
        return "<primseg.Mesh: " + std::to_string(self.mesh->vertex_count()) + " vertices, " +
               std::to_string(self.mesh->face_count()) + " faces, " +
               std::to_string(self.mesh->triangle_count()) + " triangles>";
      });

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

  const char* segment_doc =
      R"(segment(mesh, *, primitives=("plane", "cylinder", "sphere"), weights="area", threads=0, exact_costs=False, eager=False) -> Hierarchy
segment(V, F, *, ...) -> Hierarchy

Builds the whole hierarchy, with the GIL released. The input is a Mesh (read_mesh: labels are
per input polygon, like the CLI's) or arrays V (n, 3) float32/float64 and F (m, 3)
int32/int64/uint32/uint64, C- or Fortran-ordered, read in place without a converted copy
(labels are per row of F).
primitives: names or one name ("plane", "cylinder", "sphere"); weights: "area" or "uniform";
threads: 0 for all cores (the tree does not depend on it); exact_costs: slow reference mode;
eager: evaluate every candidate at once (reference mode, the same tree).
Raises InvalidInputError (a ValueError) for bad arrays (shape, dtype, NaN or infinite
coordinates, index out of range, no faces) or bad options.)";
  m.def(
      "segment",
      [](const py::object& first, const py::object& faces, const py::object& primitives,
         const std::string& weights, unsigned threads, bool exact_costs, bool eager) {
        const HierarchyOptions options =
            hierarchy_options(primitives, weights, threads, exact_costs, eager);
        if (py::isinstance<PyMesh>(first)) {
          if (!faces.is_none()) throw InvalidInputError("segment(mesh) takes no F");
          return segment_mesh(first.cast<const PyMesh&>().mesh, options);
        }
        if (faces.is_none()) throw InvalidInputError("segment(V, F): F is missing");
        return segment_mesh(mesh_from_python(first, faces), options);
      },
      py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(),
      py::arg("primitives") = py::make_tuple("plane", "cylinder", "sphere"),
      py::arg("weights") = "area", py::arg("threads") = 0u, py::arg("exact_costs") = false,
      py::arg("eager") = false,
      join_docs(
          {segment_doc, cpp_doc("build_hierarchy", doc::hierarchy__build_hierarchy_2),
           cpp_doc("HierarchyOptions::primitives", doc::hierarchy__HierarchyOptions__primitives),
           cpp_doc("HierarchyOptions::weights", doc::hierarchy__HierarchyOptions__weights),
           cpp_doc("HierarchyOptions::threads", doc::hierarchy__HierarchyOptions__threads),
           cpp_doc("HierarchyOptions::evaluation", doc::hierarchy__HierarchyOptions__evaluation),
           cpp_doc("HierarchyOptions::exact_costs", doc::hierarchy__HierarchyOptions__exact_costs)})
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
          [](const PyHierarchy& self, std::optional<std::int64_t> k,
             std::optional<double> tolerance, std::optional<double> relative_tolerance) {
            Segmentation level;
            {
              py::gil_scoped_release release;
              level = cut_level(*self.hierarchy, k, tolerance, relative_tolerance);
            }
            const py::ssize_t faces = static_cast<py::ssize_t>(level.labels.size());
            return adopt<std::int32_t>(std::move(level.labels), {faces});
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(),
          join_docs({R"(cut(k=None, *, tolerance=None, relative_tolerance=None) -> numpy.ndarray

The cluster of each input face, int32 (F,), values 0..K-1 numbered by decreasing area: the same
labels as the CLI's --labels.)",
                     kLevelArguments, cpp_doc("cut_by_count", doc::cut__cut_by_count),
                     cpp_doc("cut_by_tolerance", doc::cut__cut_by_tolerance)})
              .c_str())
      .def(
          "clusters",
          [](const PyHierarchy& self, std::optional<std::int64_t> k,
             std::optional<double> tolerance, std::optional<double> relative_tolerance) {
            std::vector<ClusterReport> reports;
            {
              py::gil_scoped_release release;
              reports = describe_clusters(
                  *self.hierarchy, cut_level(*self.hierarchy, k, tolerance, relative_tolerance));
            }
            py::list clusters;
            for (const ClusterReport& report : reports) clusters.append(cluster_dict(report));
            return clusters;
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(),
          join_docs({R"(clusters(k=None, *, tolerance=None, relative_tolerance=None) -> list of dict

One dict per cluster, in label order, with the keys and values of the CLI's --json "clusters":
id, type ("plane", "cylinder", "sphere"), faces (count), area, rms, max, and params (input
units: plane {normal, point}, sphere {center, radius}, cylinder {axis, point, radius}; vectors
as lists). json.dumps() takes it as it is.)",
                     kLevelArguments, cpp_doc("ClusterReport", doc::cut__ClusterReport),
                     cpp_doc("ClusterReport::rms", doc::cut__ClusterReport__rms),
                     cpp_doc("ClusterReport::max", doc::cut__ClusterReport__max),
                     cpp_doc("named_parameters", doc::primitive__named_parameters)})
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
      .def("__repr__", [](const PyHierarchy& self) {
        return "<primseg.Hierarchy: " + std::to_string(self.hierarchy->face_count()) + " faces, " +
               std::to_string(self.hierarchy->component_count()) + " components>";
      });
}
