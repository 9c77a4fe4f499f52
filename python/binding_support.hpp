// What several binding files share: docstrings that quote the C++ ones, numpy arrays in and out,
// the Python objects of a mesh and a hierarchy, the GIL and progress helpers, and the parsers of
// the arguments several functions take, so that they check them and word their errors alike.

#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
// In every file that converts arguments: pybind11's casters of one C++ type must be the same in
// all the translation units of a module.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "primseg/borders.hpp"
#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh.hpp"
#include "primseg/relations.hpp"

namespace py = pybind11;

namespace primseg::python {

// The Doxygen text of the public headers, generated into doxygen_docstrings.hpp (included by the
// files that quote it).
namespace doxygen {}
namespace doc = doxygen;

std::string join_docs(std::initializer_list<std::string> parts);

std::string cpp_doc(const char* name, const char* text);

// "1 face", "2 faces" (for the reprs).
std::string count_of(std::uint64_t count, const std::string& noun, const std::string& plural = "");

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
py::array as_numpy_array(const py::handle& object);

// A numpy view of `object` (any array-like, see as_numpy_array), checked to be (n, 3) of an
// accepted kind and size. `owner` keeps the array alive.
ArrayView view_n_by_3(const py::handle& object, const char* name, const char* accepted,
                      bool floating, py::object& owner);

template <typename T>
T element(const ArrayView& a, py::ssize_t row, py::ssize_t column) {
  T value;
  std::memcpy(&value, a.data + row * a.row_stride + column * a.column_stride, sizeof(T));
  return value;
}

std::string entry(const char* name, py::ssize_t row, py::ssize_t column);

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

// The mesh of arrays V and F (any array-likes, read in place), built without the GIL.
std::shared_ptr<const Mesh> mesh_from_python(const py::handle& vertices, const py::handle& faces);

// ---------------------------------------------------------------------------------------------
// Arrays out: read-only views of the C++ storage, which their base object keeps alive.

py::array read_only(py::array array);

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

// A Mesh's pickled state (Mesh's pickle, and the mesh in Skeleton's), and the Mesh it pickled.
py::tuple mesh_state(const PyMesh& self);
PyMesh mesh_from_state(const py::tuple& state);

// The HierarchyOptions of segment's primitives, weights, threads, exact_costs, eager,
// merge_batch_tolerance and regions, checked (InvalidInputError naming the bad one).
HierarchyOptions hierarchy_options(const py::object& primitives, const std::string& weights,
                                   unsigned threads, bool exact_costs, bool eager,
                                   double merge_batch_tolerance = 0, unsigned regions = 1);

// Thrown from a build's progress callback to stop it once Python has an exception to raise: a
// signal's (Ctrl-C: KeyboardInterrupt) or the user's progress callable's. The Python error stays
// set, and the binding raises it once it holds the GIL again.
struct PythonErrorPending {};

// The progress callback of a hierarchy built without the GIL: it takes the GIL (about every
// percent of the merges) to let Python handle signals and to call `progress` (None, or a callable
// taking the fraction done): either can stop the build by raising, through PythonErrorPending.
// Made, and destroyed, while the GIL is held: it holds a reference to `progress`.
std::function<void(double)> python_progress(const py::object& progress);

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

// A level as Python gives it: k (a count or "auto"), tolerance or relative_tolerance.
using ClusterCount = std::optional<std::variant<std::int64_t, std::string>>;
struct LevelArguments {
  ClusterCount k;
  std::optional<double> tolerance, relative_tolerance;
};

// Throws InvalidInputError unless the level can be cut from a mesh of `face_count` faces:
// checked before any hierarchy is built.
void validate_level(const LevelArguments& level, std::uint32_t face_count);

// The segmentation of a level, as the CLI's --clusters K|auto and --tolerance T|T% cut it.
Segmentation cut_level(const Hierarchy& hierarchy, const LevelArguments& level);

py::list vector_list(const Vec3& v);

// A cluster as the CLI's --json "clusters" writes it.
py::dict cluster_dict(const ClusterReport& report);

// The CLI's JSON "relations": one dict {kind, clusters, deviation} per relation.
py::list relations_list(const std::vector<ClusterRelation>& relations);

// A border as the CLI's --json "borders" writes it.
py::dict border_dict(const ClusterBorder& border);

// The mesh of a `mesh_or_V, F` argument pair: a Mesh (F must be None) or arrays V and F.
// `function` names the caller in messages.
std::shared_ptr<const Mesh> mesh_argument(const std::string& function, const py::object& first,
                                          const py::object& faces);

// The first arguments of write_mesh, render and read_skeleton: a Mesh, a Hierarchy (its mesh) or
// arrays V, F.
std::shared_ptr<const Mesh> mesh_or_tree_argument(const std::string& function,
                                                  const py::object& first, const py::object& faces);

// A Python number as a double, or InvalidInputError naming `what`.
double number_argument(const py::handle& value, const std::string& what);

// A Python integer in [0, limit], or InvalidInputError naming `what`.
std::uint64_t unsigned_argument(const py::handle& value, const std::string& what,
                                std::uint64_t limit = std::numeric_limits<std::uint64_t>::max());

// (n, 3) float64 positions, adopted (no copy).
py::array positions_array(std::vector<Vec3>&& positions);

// The hierarchy options of denoise and skeleton: those of a given Hierarchy (primitives and
// weights must then be None) with these threads and regions, else the arguments with
// `default_primitives`.
HierarchyOptions tool_hierarchy_options(const std::string& function, const PyHierarchy* given,
                                        const py::object& primitives, const py::object& weights,
                                        unsigned threads, unsigned regions,
                                        const py::object& default_primitives);

}  // namespace primseg::python
