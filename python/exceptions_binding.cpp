// primseg.Error (RuntimeError) and its subclasses, which are also the matching built-in kinds, so
// that `except OSError` or `except ValueError` catch them too; and the C++ exceptions' translation.

#include <exception>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "binding_support.hpp"
#include "bindings.hpp"
#include "doxygen_docstrings.hpp"
#include "primseg/error.hpp"

namespace primseg::python {
namespace {

py::object new_exception(py::module_& module, const char* name, const char* doc, py::tuple bases) {
  const std::string qualified = std::string("primseg.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), /*dict=*/nullptr);
  if (!type) throw py::error_already_set();
  py::object object = py::reinterpret_steal<py::object>(type);
  module.add_object(name, object);
  return object;
}

}  // namespace

void bind_exceptions(py::module_& m) {
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

}  // namespace primseg::python
