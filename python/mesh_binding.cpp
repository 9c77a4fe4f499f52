// Mesh, from numpy arrays or read_mesh(), and what takes any mesh: write_mesh() and render().

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "binding_support.hpp"
#include "bindings.hpp"
#include "doxygen_docstrings.hpp"
#include "primseg/denoise.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh.hpp"
#include "primseg/mesh_info.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/render.hpp"

namespace primseg::python {
namespace {

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

}  // namespace

void bind_mesh(py::module_& m) {
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
          [](const PyMesh& self, bool noise) {
            MeshInfo i;
            std::optional<std::string> out_of_range;
            std::optional<double> noise_estimate;
            {
              py::gil_scoped_release release;
              i = describe_mesh(*self.mesh);
              try {
                check_geometric_range(*self.mesh);
              } catch (const InvalidInputError& error) {
                out_of_range = error.what();
              }
              if (noise && !out_of_range) noise_estimate = estimate_noise(*self.mesh);
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
            if (noise)
              d["noise_estimate"] =
                  noise_estimate ? py::object(py::float_(*noise_estimate)) : py::none();
            return d;
          },
          py::kw_only(), py::arg("noise") = false,
          join_docs({R"(info(*, noise=False) -> dict

What `primseg info` prints, as a dict: vertices, isolated_vertices, faces, polygons (faces of
more than 3 vertices), triangles, components, boundary_edges, non_manifold_edges,
degenerate_triangles, duplicate_triangles, inconsistent_edges (edges whose two triangles are
listed in the same direction along it), inward_components (closed components facing inwards),
bbox_min, bbox_max, bbox_diagonal, and
out_of_range: None, or the message the other functions would raise for coordinates too large
or too spread out to fit reliably. With noise=True (info --noise) also noise_estimate: the noise
along the normals in input units, as denoise(k="auto") estimates it (estimate_noise: how far
bilateral smoothing moves the vertices, RMS; on a coarse mesh curvature counts too), a guide for
segment's tolerance; None when out of range. It smooths a copy of the mesh: seconds on a million
faces.)",
                     cpp_doc("describe_mesh", doc::mesh_info__file),
                     cpp_doc("check_geometric_range", doc::mesh__check_geometric_range),
                     cpp_doc("estimate_noise", doc::denoise__estimate_noise)})
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
}

}  // namespace primseg::python
