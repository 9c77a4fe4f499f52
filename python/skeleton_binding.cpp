// Skeleton: skeleton() (`primseg skeleton`), read_skeleton(), and the class's skin weights, poses
// (`primseg deform`) and glTF.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "binding_support.hpp"
#include "bindings.hpp"
#include "doxygen_docstrings.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skeleton_gltf.hpp"
#include "primseg/skeleton_io.hpp"
#include "primseg/skinning.hpp"

namespace primseg::python {
namespace {

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

// read_skeleton(), bound after the class it returns so that its signature names it.
void bind_read_skeleton(py::module_& m) {
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
}

}  // namespace

void bind_skeleton(py::module_& m) {
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
         const py::object& primitives, const py::object& weights, const std::string& joints,
         unsigned threads, unsigned regions, const py::object& progress) {
        const LevelArguments level{std::move(k), tolerance, relative_tolerance};
        const PyHierarchy* given =
            py::isinstance<PyHierarchy>(first) ? &first.cast<const PyHierarchy&>() : nullptr;
        if (given && !faces.is_none())
          throw InvalidInputError("skeleton(hierarchy) takes no F (give the level as k=...)");
        SkeletonOptions skeleton_options;
        const std::optional<JointRule> rule = joint_rule_from_string(joints);
        if (!rule)
          throw InvalidInputError("skeleton: joints='" + joints + "' is not 'paper' or 'limbs'");
        skeleton_options.joints = *rule;
        const HierarchyOptions options = tool_hierarchy_options(
            "skeleton", given, primitives, weights, threads, regions, py::make_tuple("cylinder"));
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
              extract_skeleton(*hierarchy, cut_level(*hierarchy, level), skeleton_options));
          return skeleton;
        });
      },
      py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(), py::arg("k") = py::none(),
      py::arg("tolerance") = py::none(), py::arg("relative_tolerance") = py::none(),
      py::arg("primitives") = py::none(), py::arg("weights") = py::none(),
      py::arg("joints") = std::string(to_string(SkeletonOptions{}.joints)), py::arg("threads") = 0u,
      py::arg("regions") = 1u, py::arg("progress") = py::none(),
      join_docs(
          {R"(skeleton(mesh, *, k=None, tolerance=None, relative_tolerance=None, primitives=None, weights=None, joints="paper", threads=0, regions=1, progress=None) -> Skeleton
skeleton(V, F, *, ...) -> Skeleton
skeleton(hierarchy, *, ...) -> Skeleton

`primseg skeleton`: the deformation skeleton of a level, one bone per cluster. The input is a
Mesh, arrays V and F, or a Hierarchy (its tree, not built again). Level: k (count or "auto"),
tolerance or relative_tolerance as in Hierarchy.cut (the CLI asks for --clusters K|auto).
primitives: cylinders only by default, as the CLI (and the paper) do; weights: "area" by
default. joints: "paper" (touching boundaries merge into locked hubs) or "limbs" (a protruding
part also turns where it is attached), as the CLI's --joints. regions: --regions, as in segment. The GIL is released while it works; Ctrl-C (KeyboardInterrupt) stops the hierarchy's
build, and progress, if given, is called during it with the fraction done, as in segment.)",
           cpp_doc("skeleton.hpp", doc::skeleton__file)})
          .c_str());
  bind_read_skeleton(m);
}

}  // namespace primseg::python
