// A tiny planar biped for the skill engine's tests: a pelvis on the planar root (x, z,
// pitch), a chest on a waist hinge, two legs of hip, knee and ankle hinges with flat feet,
// 1.0 m tall standing, 30 kg. tiny_biped::task(skill) writes the model, its character file,
// the skill file and a task naming them into a scratch directory and loads the task.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include "support/text_files.h"
#include "task/task.h"

namespace diverse::tiny_biped {

inline const char* kModel = R"(<mujoco model="tiny_biped">
  <compiler angle="radian" inertiafromgeom="true" autolimits="true"/>
  <option timestep="0.002" integrator="Euler" gravity="0 0 -9.81"/>
  <default>
    <joint type="hinge" axis="0 -1 0" armature="0.01" limited="true" damping="5"/>
    <geom type="capsule" contype="1" conaffinity="0" condim="3" friction="1 0.005 0.0001"/>
    <motor ctrllimited="false"/>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="20 2 0.1" contype="0" conaffinity="1"/>
    <body name="pelvis" pos="0 0 0.5">
      <joint name="root_x" type="slide" axis="1 0 0" limited="false" armature="0" damping="0"/>
      <joint name="root_z" type="slide" axis="0 0 1" limited="false" armature="0" damping="0"/>
      <joint name="root_pitch" type="hinge" axis="0 -1 0" limited="false" armature="0" damping="0"/>
      <geom name="pelvis" fromto="0 0 0 0 0 0.1" size="0.08" mass="8"/>
      <body name="chest" pos="0 0 0.12">
        <joint name="waist" range="-1 1"/>
        <geom name="chest" fromto="0 0 0 0 0 0.35" size="0.08" mass="10"/>
      </body>
      <body name="thigh_l" pos="0 0.06 0">
        <joint name="hip_l" range="-1 2.5"/>
        <geom name="thigh_l" fromto="0 0 0 0 0 -0.22" size="0.04" mass="3"/>
        <body name="shin_l" pos="0 0 -0.22">
          <joint name="knee_l" range="-2.6 0"/>
          <geom name="shin_l" fromto="0 0 0 0 0 -0.22" size="0.035" mass="2"/>
          <body name="foot_l" pos="0 0 -0.22">
            <joint name="ankle_l" range="-0.9 0.9"/>
            <geom name="foot_l" fromto="-0.04 0 -0.03 0.12 0 -0.03" size="0.025" mass="1"/>
          </body>
        </body>
      </body>
      <body name="thigh_r" pos="0 -0.06 0">
        <joint name="hip_r" range="-1 2.5"/>
        <geom name="thigh_r" fromto="0 0 0 0 0 -0.22" size="0.04" mass="3"/>
        <body name="shin_r" pos="0 0 -0.22">
          <joint name="knee_r" range="-2.6 0"/>
          <geom name="shin_r" fromto="0 0 0 0 0 -0.22" size="0.035" mass="2"/>
          <body name="foot_r" pos="0 0 -0.22">
            <joint name="ankle_r" range="-0.9 0.9"/>
            <geom name="foot_r" fromto="-0.04 0 -0.03 0.12 0 -0.03" size="0.025" mass="1"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="m_waist" joint="waist" forcelimited="true" forcerange="-150 150"/>
    <motor name="m_hip_l" joint="hip_l" forcelimited="true" forcerange="-200 200"/>
    <motor name="m_knee_l" joint="knee_l" forcelimited="true" forcerange="-200 200"/>
    <motor name="m_ankle_l" joint="ankle_l" forcelimited="true" forcerange="-100 100"/>
    <motor name="m_hip_r" joint="hip_r" forcelimited="true" forcerange="-200 200"/>
    <motor name="m_knee_r" joint="knee_r" forcelimited="true" forcerange="-200 200"/>
    <motor name="m_ankle_r" joint="ankle_r" forcelimited="true" forcerange="-100 100"/>
  </actuator>
</mujoco>
)";

inline const char* kCharacter = R"(name = "tiny_biped"
description = "A tiny planar biped for tests."
model = "tiny_biped.xml"
[root]
kind = "planar"
body = "pelvis"
x = "root_x"
z = "root_z"
pitch = "root_pitch"
wja = 1.0
[[groups]]
name = "hip"
role = "hip"
plane = "sagittal"
joints = ["hip_l", "hip_r"]
wja = 1.0
kp = 300.0
kd = 30.0
[[groups]]
name = "knee"
role = "knee"
plane = "sagittal"
joints = ["knee_l", "knee_r"]
wja = 1.0
kp = 300.0
kd = 30.0
[[groups]]
name = "ankle"
role = "ankle"
plane = "sagittal"
joints = ["ankle_l", "ankle_r"]
wja = 0.0
kp = 150.0
kd = 15.0
[[groups]]
name = "waist"
role = "waist"
plane = "sagittal"
joints = ["waist"]
wja = 1.0
kp = 300.0
kd = 30.0
[feet]
bodies = ["foot_l", "foot_r"]
)";

// The scratch directory of this process.
inline std::filesystem::path dir() {
  const auto d = std::filesystem::temp_directory_path() / ("diverse_tiny_biped_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

// Writes the skill file `name`.toml; returns its path.
inline std::string write_skill(const std::string& name, const std::string& skill) {
  const std::string path = (dir() / (name + ".toml")).string();
  test_files::write_text(path, skill);
  return path;
}

// A skill for the tiny biped: the target sets (stand, crouch, push, tuck), the gain set
// `stiff` and a J^T balance module `balance` the engine's tests share, then `rest`
// (modules and phases).
inline std::string skill(const std::string& rest) {
  return R"(name = "tiny"
root = "planar"
pairs = ["hip", "knee", "ankle"]
[targets.stand]
hip = { value = 0.0, world = "parent" }
ankle = { value = 0.0, world = "child" }
other = 0.0
[targets.crouch]
hip = { value = -0.3, world = "parent" }
ankle = { value = 0.0, world = "child" }
knee = -1.4
other = 0.0
[targets.push]
hip = { value = 0.0, world = "parent" }
ankle = { value = 0.5, world = "child" }
knee = 0.0
other = 0.0
[targets.tuck]
hip = 1.0
knee = -1.2
other = 0.0
[gains.stiff]
hip = { kp = 1500.0, kd = 40.0 }
knee = { kp = 1500.0, kd = 40.0 }
ankle = { kp = 600.0, kd = 20.0 }
[[modules]]
name = "balance"
kind = "balance"
kp = 1000.0
kd = 200.0
max_force = 200.0
)" + rest;
}

// A task of the tiny biped under the skill `skill` (the text of a skill file): no landing
// box, no constraint terms but falls.
inline Task task(const std::string& name, const std::string& skill, const std::string& controller_extra = "") {
  test_files::write_text((dir() / "tiny_biped.xml").string(), kModel);
  test_files::write_text((dir() / "tiny_biped.toml").string(), kCharacter);
  const std::string skill_file = write_skill(name + "_skill", skill);
  const std::string task_file = (dir() / (name + ".toml")).string();
  test_files::write_text(task_file, "name = \"" + name + "\"\ncharacter = \"tiny_biped.toml\"\nmetric = \"md\"\n" +
                                        "variations = 1\nm0 = \"none.json\"\n[controller]\nskill = \"" + skill_file + "\"\n" +
                                        controller_extra + "\n[constraints]\nweight = 1.0\nfall_penalty = 1.0\n");
  return load_task(task_file);
}

}  // namespace diverse::tiny_biped
