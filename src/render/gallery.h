// The interactive gallery of a run (`diverse gallery RUN`): one self-contained HTML file,
// RUN/gallery.html, that any browser opens from disk with no network.
//
// The page (source in web/, bundled with three.js into a template at build time; see
// docs/guide/viewing-results.md) shows all motions side by side in 3D, in step, with play/pause,
// a time scrubber and half speed; each motion's constraint value C and its distances to
// the others (summary.json, every motion metric); and, per variation, a slider along its
// optimization path (paper figure 6a).
//
// What the page shows is gathered from the run by finished/gallery_data.h
// (collect_gallery_data: figures, distances, path points simulated, progress, shapes,
// robustness, blends, poses); here it becomes the page's JSON (gallery_json):
//   - per model: its bodies and geoms (type, size, body, position and quaternion in the
//     body frame, colour); the world body's geoms (boxes, obstacles) are the scene; models
//     the same in every number are listed once;
//   - per motion, path point and blend: the world position and orientation (xpos, xquat
//     from mj_kinematics) of every body at each of its poses; numbers are rounded to 4
//     decimals (0.1 mm, 1e-4 of a unit quaternion), which keeps a run of 5 motions and 4
//     paths at a few megabytes;
//   - how the page first looks at the motions (render/view_plan.h), as the film strip
//     does, and the task's landing region on the floor (render/run_media.h);
//   - the rest as collected: figures, distances, progress, shapes, robustness (null and a
//     note for a run without the suite: the page says the suite was not run), blends.
#pragma once

#include <mujoco/mujoco.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "finished/gallery_data.h"
#include "finished/run_view.h"
#include "render/offscreen.h"

namespace diverse {

// What to collect (finished/gallery_data.h) and the page template.
struct GalleryOptions : GalleryDataOptions {
  std::filesystem::path page_template;  // "" = gallery_template_path()
};

// The page template built from web/: the environment variable DIVERSE_GALLERY_TEMPLATE if
// set; else, for an installed program, PREFIX/share/diverse/gallery-template.html beside
// its bin/; else the path fixed at build time. Throws UserError saying what is missing
// (node and npm, or `npm ci` in web/) if it does not exist.
std::filesystem::path gallery_template_path();

// The model's bodies and geoms, as the page draws them (see above).
nlohmann::json model_json(const mjModel* model);
// Per frame, xpos (3) and xquat (4, w first) of bodies 1 .. nbody-1, rounded, flattened.
nlohmann::json body_frames_json(const mjModel* model, std::span<const std::vector<double>> frames);

// The page's data (see above) from what was collected and the ground strips to draw.
nlohmann::json gallery_json(const GalleryData& data, std::span<const GroundStrip> strips);

// gallery_json of the run's collected data and its landing region; throws as
// collect_gallery_data does.
nlohmann::json gallery_data(const RunView& run, const GalleryOptions& options = {});

// The template with the data put in its place (JSON inside a <script> element, with "</"
// escaped). Throws UserError if the template lacks the data marker.
std::string gallery_html(const std::string& page_template, const nlohmann::json& data);

// Reads the run, makes the data and writes RUN/gallery.html; returns its path.
std::filesystem::path write_gallery(const std::filesystem::path& run_dir,
                                    const GalleryOptions& options = {});

}  // namespace diverse
