#include "render/film_strip.h"

#include <algorithm>
#include <map>
#include <memory>
#include <cstdio>
#include <stdexcept>

#include "render/view_plan.h"

namespace diverse {
namespace {

constexpr FontSize kLabelFont = FontSize::kLarge;
constexpr FontSize kTitleFont = FontSize::kMedium;
constexpr int kLabelPad = 8;  // px between a label and the tiles

void check_rows(std::span<const FilmRow> rows) {
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].model == nullptr) {
      throw std::invalid_argument("film strip: row " + std::to_string(i) + " has no model");
    }
  }
}

}  // namespace

std::string column_label(int index) {
  std::string label;
  for (int n = index + 1; n > 0; n = (n - 1) / 26) {
    label.insert(label.begin(), static_cast<char>('A' + (n - 1) % 26));
  }
  return label;
}

Image render_film_strip(std::span<const FilmRow> rows, const FilmStripOptions& options) {
  check_rows(rows);
  const int tile_w = options.tile_width;
  const int tile_h = options.tile_height;
  std::size_t columns = options.column_labels.size();
  for (const FilmRow& row : rows) columns = std::max(columns, row.frames.size());

  std::vector<PosedModel> motions;
  for (const FilmRow& row : rows) motions.push_back({row.model, row.frames});
  const double aspect = static_cast<double>(tile_w) / tile_h;
  std::vector<std::vector<std::array<double, 3>>> anchors(rows.size());
  if (options.follow) {
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (const std::vector<double>& qpos : rows[r].frames)
        anchors[r].push_back(qpos.empty() ? std::array<double, 3>{0, 0, 0}
                                          : follow_anchor(rows[r].model, qpos));
  }
  const SideCamera camera =
      options.camera ? *options.camera
      : options.follow
          ? fit_following_camera(motions, anchors, aspect, options.camera_direction,
                                 options.camera_margin)
          : fit_shared_camera(motions, aspect, options.ground_strips, options.camera_direction,
                              options.camera_margin);

  // Layout: an optional title line, a line of column labels, then the rows of tiles with
  // their labels to the left.
  int label_w = 0;
  for (const FilmRow& row : rows) label_w = std::max(label_w, text_width(row.label, kLabelFont));
  if (label_w > 0) label_w += kLabelPad;
  const int title_h = options.title.empty() ? 0 : text_height(kTitleFont) + kLabelPad;
  const int header_h = text_height(kLabelFont) + kLabelPad / 2;
  const int n_cols = static_cast<int>(columns);
  const int n_rows = static_cast<int>(rows.size());
  const int grid_x = options.margin + label_w;
  const int grid_y = options.margin + title_h + header_h;
  const int width = std::max(grid_x + n_cols * tile_w + std::max(n_cols - 1, 0) * options.gap,
                             grid_x + text_width(options.title, kTitleFont)) +
                    options.margin;
  const int height = grid_y + n_rows * tile_h + std::max(n_rows - 1, 0) * options.gap +
                     options.margin;
  Image canvas(std::max(width, 1), std::max(height, 1), options.background);

  if (!options.title.empty()) {
    draw_text(canvas, options.title, grid_x, options.margin, options.text, kTitleFont);
  }
  for (int c = 0; c < n_cols; ++c) {
    const std::string label = c < static_cast<int>(options.column_labels.size())
                                  ? options.column_labels[c]
                                  : column_label(c);
    const int x = grid_x + c * (tile_w + options.gap) + tile_w / 2;
    draw_text(canvas, label, x, options.margin + title_h, options.text, kLabelFont,
              Align::kCenter);
  }

  // One renderer per distinct model; rows that share a model share its GL context.
  std::map<const mjModel*, std::unique_ptr<OffscreenRenderer>> renderers;
  for (int r = 0; r < n_rows; ++r) {
    const FilmRow& row = rows[r];
    auto& renderer = renderers[row.model];
    if (!renderer) {
      renderer = std::make_unique<OffscreenRenderer>(row.model, tile_w, tile_h, options.style);
      renderer->set_ground_strips(options.ground_strips);
    }
    const int y = grid_y + r * (tile_h + options.gap);
    draw_text(canvas, row.label, grid_x - kLabelPad, y + (tile_h - text_height(kLabelFont)) / 2,
              options.text, kLabelFont, Align::kRight);
    for (int c = 0; c < n_cols; ++c) {
      const int x = grid_x + c * (tile_w + options.gap);
      canvas.fill_rect(x - 1, y - 1, tile_w + 2, tile_h + 2, options.tile_border);
      if (c < static_cast<int>(row.frames.size()) && !row.frames[c].empty()) {
        if (options.follow) {
          const auto& anchor = anchors[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
          Image tile = renderer->render(row.frames[c], at_anchor(camera, anchor));
          char where[48];
          std::snprintf(where, sizeof where, "x %.1f m", anchor[0]);
          draw_text(tile, where, tile_w - 6, tile_h - 6 - text_height(FontSize::kSmall), options.text,
                    FontSize::kSmall, Align::kRight);
          canvas.paste(tile, x, y);
        } else {
          canvas.paste(renderer->render(row.frames[c], camera), x, y);
        }
      } else {
        canvas.fill_rect(x, y, tile_w, tile_h, options.background);
      }
    }
  }
  return canvas;
}

void write_film_strip(const std::string& path, std::span<const FilmRow> rows,
                      const FilmStripOptions& options) {
  write_png(path, render_film_strip(rows, options));
}

}  // namespace diverse
