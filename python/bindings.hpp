// The bind_* functions module.cpp calls, in the order it must call them: one concept's Python
// names each, defined in the <concept>_binding.cpp of that name.

#pragma once

#include <pybind11/pybind11.h>

#include "binding_support.hpp"

namespace primseg::python {

void bind_exceptions(py::module_& m);

// The Hierarchy class alone, registered before the functions that return it (their signatures
// then name it); bind_hierarchy adds its methods.
py::class_<PyHierarchy> declare_hierarchy_class(py::module_& m);
void bind_hierarchy(py::module_& m, py::class_<PyHierarchy>& hierarchy_class);

void bind_mesh(py::module_& m);
void bind_denoise(py::module_& m);
void bind_skeleton(py::module_& m);
void bind_distance(py::module_& m);

}  // namespace primseg::python
