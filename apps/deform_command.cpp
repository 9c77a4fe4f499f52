#include <cstdio>
#include <memory>

#include "command.hpp"
#include "limits.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/skeleton_io.hpp"
#include "primseg/skinning.hpp"
#include "skeleton_outputs.hpp"

namespace primseg::cli {

Command add_deform_command(CLI::App& app) {
  struct Options {
    std::string mesh_path, skeleton_path, pose_path, output;
    double band = SkinningOptions{}.band;
    SkeletonPicture picture;
    bool quiet = false;
    ResourceLimits limits;
  };
  auto o = std::make_shared<Options>();
  auto* command = app.add_subcommand(
      "deform",
      "Pose a mesh: rotate joints of its skeleton, move vertices by linear blend skinning");
  command
      ->add_option("MESH", o->mesh_path,
                   "The mesh the skeleton was extracted from (- for standard input)")
      ->required();
  command->add_option("SKELETON", o->skeleton_path, "Skeleton file of primseg skeleton")
      ->required();
  command
      ->add_option("POSE", o->pose_path,
                   "Pose file: {\"rotations\": [{\"joint\": J, \"axis\": [x, y, z], \"degrees\": "
                   "A}]}")
      ->required();
  command->add_option("-o,--output", o->output, "Posed mesh (.off .obj .ply .stl)")->required();
  command
      ->add_option("--band", o->band,
                   "Skinning blend half-width on each side of a boundary, in bone radii")
      ->capture_default_str();
  o->picture.add_options(*command, "the posed mesh and skeleton");
  command->add_flag("--quiet,-q", o->quiet, "No summary output");
  add_limit_options(*command, o->limits, kMeshBytesPerFace);

  return {command, [o] {
            if (!(std::isfinite(o->band) && o->band >= 0))
              throw InvalidInputError("--band: must be a finite number >= 0");
            mesh_format_from_path(o->output);  // an unknown extension fails before any work
            const Mesh mesh =
                read_geometry_within(o->mesh_path, o->limits, o->picture.png ? kPictureBytes : 0);
            const Skeleton skeleton = read_skeleton(o->skeleton_path);
            const std::vector<JointRotation> pose = read_pose(o->pose_path);
            if (skeleton.face_labels.size() != mesh.face_count())
              throw InvalidInputError("'" + o->skeleton_path + "' was made from a mesh of " +
                                      std::to_string(skeleton.face_labels.size()) + " faces, " +
                                      input_name(o->mesh_path) + " has " +
                                      std::to_string(mesh.face_count()));
            SkinningOptions skinning;
            skinning.band = o->band;
            const SkinWeights weights = compute_skin_weights(mesh, skeleton, skinning);
            const std::vector<RigidTransform> bones = pose_bones(skeleton, pose);
            Mesh posed = mesh;
            posed.positions = skin_positions(mesh.positions, weights, bones);
            write_mesh(o->output, posed);
            if (o->picture.png) {
              Skeleton posed_skeleton = skeleton;
              const std::vector<Vec3> joints = posed_joint_positions(skeleton, bones);
              for (Joint& joint : posed_skeleton.joints) joint.position = joints[joint.id];
              o->picture.write(posed, posed_skeleton);
            }
            if (!o->quiet)
              std::printf("%s: %s applied, %s\n", o->output.c_str(),
                          count_of(pose.size(), "joint rotation").c_str(),
                          count_of(posed.vertex_count(), "vertex", "vertices").c_str());
          }};
}

}  // namespace primseg::cli
