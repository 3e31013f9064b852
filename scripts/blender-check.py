"""Imports a glTF file of `diverse export --gltf` into Blender and reports what it made.

    blender -b --python scripts/blender-check.py -- RUN/export/m1.glb [--expect-bones N] [--fps 30]

Run with Blender in background mode (Debian 12: `apt-get install blender`, 3.4). Prints
one line per armature (its bones), per skinned mesh (the armature it follows) and per
action (its frame range), and exits 1 unless the file made at least one armature, each
skinned mesh follows one, and each armature has an action (and, with --expect-bones, that
many bones). The scene's frame rate is set to the export's (--fps, default 30) before the
import, so that the action has a frame per keyframe. docs/guide/engines.md shows its output.

Blender 3.4's glTF importer calls `np.bool`, which numpy 1.24 (Debian 12's) no longer has;
this script aliases it to `bool` before importing, in this Blender process only.
"""
import sys

import numpy as np

if "bool" not in vars(np):
    np.bool = bool  # Blender 3.4's io_import_scene_gltf2 uses the alias numpy 1.24 removed

import bpy  # noqa: E402


def main(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if not args:
        print("blender-check.py: expected a .glb file after --", file=sys.stderr)
        return 2
    path, expect, fps = args[0], None, 30
    if "--expect-bones" in args:
        expect = int(args[args.index("--expect-bones") + 1])
    if "--fps" in args:
        fps = int(args[args.index("--fps") + 1])
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.fps = fps
    result = bpy.ops.import_scene.gltf(filepath=path)
    if "FINISHED" not in result:
        print(f"blender-check.py: {path}: the glTF importer failed ({result})", file=sys.stderr)
        return 1
    armatures = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    meshes = [o for o in bpy.data.objects if o.type == "MESH"]
    ok = bool(armatures)
    print(f"{path}: {len(armatures)} armature(s), {len(meshes)} mesh object(s), "
          f"{len(bpy.data.actions)} action(s), Blender {bpy.app.version_string}")
    for a in armatures:
        bones = a.data.bones
        roots = [b.name for b in bones if b.parent is None]
        action = a.animation_data.action if a.animation_data else None
        print(f"armature {a.name}: {len(bones)} bones (root {', '.join(roots)}), "
              f"action {action.name if action else 'none'}")
        ok = ok and action is not None and (expect is None or len(bones) == expect)
    for m in meshes:
        modifiers = [mod.object.name for mod in m.modifiers if mod.type == "ARMATURE" and mod.object]
        if modifiers or m.vertex_groups:
            print(f"skinned mesh {m.name}: {len(m.data.vertices)} vertices, {len(m.vertex_groups)} vertex groups, "
                  f"follows {', '.join(modifiers) or 'no armature'}")
            ok = ok and bool(modifiers)
    for action in bpy.data.actions:
        start, end = action.frame_range
        print(f"action {action.name}: frames {start:g} to {end:g}, {len(action.fcurves)} curves")
    humanoid = {}
    for a in armatures:
        for bone in a.data.bones:
            if "humanoid_bone" in bone:
                humanoid[bone.name] = bone["humanoid_bone"]
    if humanoid:
        print("humanoid bones: " + ", ".join(f"{k} {v}" for k, v in humanoid.items()))
    print("ok" if ok else "FAILED")
    return 0 if ok else 1


sys.exit(main(sys.argv))
