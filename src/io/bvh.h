// BVH motion files (Biovision Hierarchy), for taking motions into animation tools.
//
// A BVH file is a skeleton (HIERARCHY: one ROOT, a JOINT per bone, each with an OFFSET from
// its parent and its CHANNELS) followed by MOTION: the frame count, the frame time and one
// line of channel values per frame, in the order the channels appear in the hierarchy.
// A joint's transform relative to its parent is
//
//   T = Translate(OFFSET + position channels) * R(rotation channels),
//
// with R the product of the rotations in channel order, R = R_first R_second R_third
// (intrinsic Euler angles, in degrees). This is how Blender's importer and three.js's
// BVHLoader read files; the format itself is described in M. Meredith and S. Maddock,
// "Motion Capture File Formats Explained" (University of Sheffield, 2001).
//
// Files made from MuJoCo models (bvh_from_model) follow these conventions:
//
//   - Units: metres (Blender: import with Scale 1.0; for tools that expect centimetres
//     scale by 100).
//   - Axes: Y up, as BVH files usually are. MuJoCo's z-up world maps to BVH by
//     (X, Y, Z)_bvh = (x, z, -y)_mujoco, a proper rotation, so Blender's default import
//     (forward -Z, up Y) brings the motion back exactly to MuJoCo's axes. The planar
//     characters face +X; their hinges about MuJoCo's -y become rotations about +Z.
//   - Skeleton: one BVH joint per moving body (the root is the child of the world body
//     that carries the model's degrees of freedom, e.g. the pelvis), placed at the body's
//     origin; OFFSET is the body's position in its parent (body_pos); leaves get an End
//     Site at the far end of their first geom.
//   - Channels: the root has Xposition Yposition Zposition Zrotation Xrotation Yrotation,
//     with its position absolute (the root OFFSET is 0, so importers that add the offset
//     and importers that do not agree) and its orientation as intrinsic Z-X-Y angles (a
//     free root, or a planar root's pitch, all in Zrotation).
//   - A body whose joints are hinges at its origin, about axes along the BVH axes, in a
//     frame not rotated against its parent's (every body of assets/characters/human2d and
//     human3d) has one rotation channel per hinge, in MuJoCo's joint order, holding the
//     hinge angle (qpos - qpos0) in degrees, negated for an axis along -X, -Y or -Z. MuJoCo
//     turns a body's joints in order, each about its axis in the frame the joints before
//     it turned, R = R(a1, q1) R(a2, q2), which is how a BVH joint composes its channels;
//     so a universal joint (pitch about MuJoCo's -y, then roll about +-x) is the two
//     channels "Zrotation Xrotation", a planar character's hinge (about -y) one Zrotation,
//     and an animator sees each joint's own angles.
//   - Every other body (ball joints, oblique or offset hinges, rotated body frames such as
//     the bird robot's legs, bodies with no joint) has Zrotation Xrotation Yrotation: the
//     Z-X-Y angles of its rotation in its parent, exact for any rotation.
//   - Each angle is unwrapped over time (no jumps of 360 degrees), so a backflip's root
//     turns smoothly.
//
// The body frames reproduce MuJoCo's exactly when every joint of a body sits at the body's
// origin and only the root translates (true of assets/characters/*.xml); other models are
// exported with their bodies' rotations but a joint that moves a body's origin is lost.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace diverse {

struct BvhJoint {
  std::string name;
  int parent = -1;                     // index into Bvh::joints; -1 for the root
  std::array<double, 3> offset{};      // from the parent's origin, in the parent's frame (m)
  std::vector<std::string> channels;   // e.g. "Xposition", "Zrotation"
  bool has_end_site = false;
  std::array<double, 3> end_site{};    // End Site offset (m), if has_end_site
};

struct Bvh {
  std::vector<BvhJoint> joints;              // parents before children, as in the file
  double frame_time = 1.0 / 30.0;            // s
  std::vector<std::vector<double>> frames;   // channel values per frame (m, degrees)

  int channel_count() const;
  int frame_count() const { return static_cast<int>(frames.size()); }
  int find(const std::string& name) const;   // joint index, or -1
};

// The file's text. Numbers are written with 6 decimals (1 micrometre, 1e-6 degree).
std::string bvh_text(const Bvh& bvh);
// Parses a BVH file's text. Throws UserError "ORIGIN: line N: expected ..." on malformed
// input (unknown keyword, missing brace, wrong number of values in a frame, ...).
Bvh parse_bvh(const std::string& text, const std::string& origin);

// bvh_text written atomically; throws UserError if the file cannot be written.
void write_bvh(const std::filesystem::path& path, const Bvh& bvh);
// Reads and parses a file; throws UserError.
Bvh read_bvh(const std::filesystem::path& path);

// World transform of every joint at one frame (forward kinematics of the file): origin
// (m, BVH axes) and rotation matrix (row-major, BVH axes).
struct BvhPose {
  std::vector<std::array<double, 3>> position;
  std::vector<std::array<double, 9>> rotation;
};
BvhPose bvh_pose(const Bvh& bvh, int frame);

// MuJoCo world coordinates to BVH coordinates: (x, y, z) -> (x, z, -y).
std::array<double, 3> mujoco_to_bvh(const double* v);

// The skeleton of `model` and one frame per qpos (each of size model->nq), sampled every
// 1 / fps seconds. `body_of_joint`, if given, receives the MuJoCo body id of each BVH
// joint. Throws UserError if the model has no moving bodies, or more than one child of
// the world body moves (a BVH file has one root), std::invalid_argument on a qpos of the
// wrong size or fps <= 0.
Bvh bvh_from_model(const mjModel* model, std::span<const std::vector<double>> qpos_frames,
                   double fps, std::vector<int>* body_of_joint = nullptr);

}  // namespace diverse
