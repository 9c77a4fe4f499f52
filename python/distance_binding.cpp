// distance(): `primseg distance --json`, Metro-style distances between two surfaces.

#include <memory>
#include <optional>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "binding_support.hpp"
#include "bindings.hpp"
#include "doxygen_docstrings.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_distance.hpp"

namespace primseg::python {
namespace {

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

}  // namespace

void bind_distance(py::module_& m) {
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

}  // namespace primseg::python
