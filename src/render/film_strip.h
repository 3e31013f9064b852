// Film strips: a grid of side views, one row per motion and one column per chosen moment.
//
// Each row is a motion (its own model, so rows may differ in body shape) with a label such
// as "M0", and a list of poses the caller picked, e.g. at the phase events of a jump; the
// columns are labelled A, B, C, ... unless labels are given. Every tile is seen through one
// shared camera fitted to all poses of all rows (and to any ground strips), so positions and
// sizes compare across the whole picture. Scene objects of the models (boxes, obstacles) are
// drawn as MuJoCo draws them; ground strips mark x-intervals of the floor such as a landing
// region. A film strip of a character that travels far (a walk) can follow it instead:
// every tile centred on its own pose, with the same camera direction and distance.
#pragma once

#include <mujoco/mujoco.h>

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "render/image.h"
#include "render/offscreen.h"

namespace diverse {

struct FilmRow {
  const mjModel* model = nullptr;
  std::string label;                        // drawn left of the row, e.g. "M0"
  // One qpos (size model->nq) per column; an empty qpos leaves that tile empty (e.g. a
  // motion that never reached the column's phase event).
  std::vector<std::vector<double>> frames;
};

struct FilmStripOptions {
  int tile_width = 240;   // px
  int tile_height = 240;  // px
  int gap = 6;            // px between tiles
  int margin = 12;        // px around the grid
  std::string title;      // optional line above the grid
  std::vector<std::string> column_labels;  // default "A", "B", ... (column_label)
  std::vector<GroundStrip> ground_strips;  // drawn on the floor; kept in view
  SideCamera camera_direction;             // azimuth, elevation and fovy of the shared camera
  double camera_margin = 0.08;             // see fit_side_camera
  std::optional<SideCamera> camera;        // use this camera instead of fitting one
  // Every tile centred on its own pose (render/view_plan.h): the camera's lookat is then
  // relative to each pose's anchor, and each tile is labelled with where the character is.
  bool follow = false;
  RenderStyle style;
  Rgb background{255, 255, 255};
  Rgb text{34, 34, 34};
  Rgb tile_border{190, 190, 190};
};

// "A".."Z", then "AA", "AB", ... for index 0, 1, ...
std::string column_label(int index);

// The film strip as an image. Rows may have different numbers of frames; missing tiles are
// left empty. Throws std::invalid_argument if a row has no model or a frame has the wrong
// size.
Image render_film_strip(std::span<const FilmRow> rows, const FilmStripOptions& options = {});

// render_film_strip written as a PNG; throws UserError if the file cannot be written.
void write_film_strip(const std::string& path, std::span<const FilmRow> rows,
                      const FilmStripOptions& options = {});

}  // namespace diverse
