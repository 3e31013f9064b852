// glTF 2.0 export of motions (binary .glb), for animation and 3D tools (Blender, three.js,
// game engines) that read it natively.
//
//   write_glb("export/m1.glb", {{model, frames, "M1"}}, 30.0);
//
// What a file holds:
//   - A skinned character (GltfOptions::skinned, the default), as Blender, three.js and
//     game engines play characters: a skeleton of one joint node per moving body, named
//     after it, nested as the bodies are (the root body a child of the motion's own node,
//     named after the motion: "M1"), with a skin whose inverse bind matrices are the
//     bodies' world transforms at the model's qpos0 inverted; and one mesh ("M1 body", a
//     node of the scene's root) of every body's geoms at that pose, each vertex bound to
//     its body's joint with weight 1. The joints of the human characters carry the
//     humanoid bone they stand for in their extras ({"humanoid_bone": "LeftUpperLeg"}:
//     Unity's and Godot's humanoid names; docs/guide/engines.md has the table).
//   - Or, not skinned: each body node with its own mesh.
//   - A body's mesh: its visible geoms (MuJoCo groups 0-2; capsules, cylinders, spheres,
//     ellipsoids and boxes, as triangle meshes with normals, in the geom's place in the
//     body) in the model's colours (geom rgba or its material's, taken as sRGB, so they look
//     as in MuJoCo and the gallery). Static scene geoms (a box to jump onto) are one more
//     node, "<motion> scene". The floor plane is left out.
//   - One animation, "motion": per body (joint) node its rotation in its parent, and the
//     translation of every node whose place in its parent changes (the root body's; any
//     body moved by a slide joint), sampled at the given frame rate from the recorded
//     states (linear interpolation, unit quaternions). Several motions in one file share
//     the animation's time axis; a shorter motion holds its last pose.
//   - Units metres; axes: glTF's Y up. MuJoCo's z-up world maps as (X, Y, Z) = (x, z, -y),
//     a proper rotation (as in the BVH files), so the characters face +X. Blender's importer
//     (+Y up, the default) brings the motion back with MuJoCo's axes.
//   - Each motion on its own model: a run whose bodies varied exports each body with its
//     own proportions.
//   - Side by side: each motion's node translated by `offset` (metres, MuJoCo axes).
// Built with tinygltf (Debian libtinygltf-dev), which writes the container; meshes and
// animation data are ours.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace diverse {

struct GltfMotion {
  const mjModel* model = nullptr;
  std::vector<std::vector<double>> frames;  // qpos (size model->nq) every 1 / fps seconds
  std::string name;                         // "M1": the motion's node and node-name prefix
  std::array<double, 3> offset{0, 0, 0};    // m, MuJoCo axes: where the motion is placed
};

struct GltfOptions {
  double fps = 30.0;
  // A skinned character (the default) or rigid body nodes (see the top of this file).
  bool skinned = true;
  int slices = 20;  // segments around a capsule, cylinder or sphere
  int stacks = 10;  // rings from pole to pole of a sphere (half of them per capsule cap)
};

// Writes the motions into one .glb file (atomically). Node names are the body names, or
// "<name> <body>" when the file holds more than one motion. Throws UserError if the file
// cannot be written, std::invalid_argument on a motion without a model or frames, or a
// qpos of the wrong size.
void write_glb(const std::filesystem::path& path, const std::vector<GltfMotion>& motions,
               const GltfOptions& options = {});

// Spacing (m, along MuJoCo's -y) that keeps the motions' bodies apart side by side: the
// widest motion's extent across y plus half a metre.
double side_by_side_spacing(const std::vector<GltfMotion>& motions);

}  // namespace diverse
