// The `primseg` Python module: meshes from files or numpy arrays, the hierarchy, its levels, its
// clusters and its SciPy linkage matrix. Docstrings quote the C++ Doxygen text (generated header).
// Each concept's names are bound in its own *_binding.cpp; this file only fixes their order.

#include <pybind11/pybind11.h>

#include "binding_support.hpp"
#include "bindings.hpp"
#include "doxygen_docstrings.hpp"

PYBIND11_MODULE(primseg, m) {
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
  bind_exceptions(m);

  // Registered before the functions that return it, so that their signatures name it.
  py::class_<PyHierarchy> hierarchy_class = declare_hierarchy_class(m);
  bind_mesh(m);                        // Mesh, read_mesh, write_mesh, render
  bind_hierarchy(m, hierarchy_class);  // segment, read_tree, the Hierarchy's methods
  bind_denoise(m);
  bind_skeleton(m);  // the Skeleton class, skeleton(), read_skeleton()
  bind_distance(m);
}
