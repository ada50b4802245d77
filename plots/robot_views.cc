// The robot figures drawn in the map's plane or along the track: the top
// view, one laser scan and the side view.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "cosim/variable_table.h"
#include "plots/figure_style.h"
#include "plots/gnuplot.h"
#include "plots/robot_run.h"

namespace linesim::plots::robot {

namespace {

using style::PlotItem;
using table::Column;

constexpr style::Canvas kCanvas{1000, 800};
// The views' plot area left and right (screen fractions); top under the
// caption's two lines; bottom above the legend band.
constexpr double kLeft = 0.08, kRight = 0.97;
const double kTop = 1.0 - 3.6 * style::kFontPx / kCanvas.height_px;

std::string Num(double x) { return cosim::FormatValue(x); }

void AppendPolygon(std::string& block, const std::array<Point, 4>& corners) {
  for (int k = 0; k <= 4; ++k) {
    const Point& p = corners[k % 4];
    block += Num(p.x) + "," + Num(p.y) + "\n";
  }
  block += "\n";
}

void AppendBlock(std::string& script, const std::string& name, const std::string& data) {
  script += "$" + name + " << EOD\n" + data + "EOD\n";
}

// An outline with a heading tick from its centre to the front.
void AppendOutline(std::string& block, double x, double y, double yaw, double length,
                   double width) {
  AppendPolygon(block, Rectangle(x, y, yaw, length, width));
  block += Num(x) + "," + Num(y) + "\n" + Num(x + 0.5 * length * std::cos(yaw)) + "," +
           Num(y + 0.5 * length * std::sin(yaw)) + "\n\n";
}

// Solids of the scene as gnuplot data: boxes as closed polygons, cylinders
// as "x,y,radius" rows for `with circles`.
struct SolidLayer {
  std::string polygons, circles;
};

// Footprint corners of `solid` moved by (dx, dy): a box's four, or the
// bounding square of a cylinder.
std::array<Point, 4> Footprint(const models::Solid& solid, double dx, double dy) {
  if (solid.kind == models::Solid::Kind::kCylinder) {
    return Rectangle(solid.x_m + dx, solid.y_m + dy, 0.0, 2.0 * solid.radius_m,
                     2.0 * solid.radius_m);
  }
  return Rectangle(solid.x_m + dx, solid.y_m + dy, solid.yaw_rad, solid.length_m, solid.width_m);
}

void AppendSolid(SolidLayer& layer, const models::Solid& solid, double dx, double dy) {
  if (solid.kind == models::Solid::Kind::kCylinder) {
    layer.circles +=
        Num(solid.x_m + dx) + "," + Num(solid.y_m + dy) + "," + Num(solid.radius_m) + "\n";
  } else {
    AppendPolygon(layer.polygons, Footprint(solid, dx, dy));
  }
}

std::array<Point, 4> BeltCorners(const models::Belt& b) {
  return Rectangle(b.area.center_x_m, b.area.center_y_m, b.area.direction_rad, b.area.length_m,
                   b.area.width_m);
}

// The scene's layers for a view: belts, obstacles, and the carried objects
// moved along their belts by `travel` (one per belt; an object past its
// belt's end has been lifted off the line and is left out).
struct SceneLayers {
  std::string belts;
  SolidLayer obstacles, carried;
  std::vector<std::array<Point, 4>> footprints;  // for framing
};
SceneLayers SceneAt(const models::Scene& scene, const std::vector<std::optional<double>>& travel,
                    bool obstacles_too, const Bounds* within = nullptr) {
  SceneLayers l;
  for (const models::Belt& b : scene.belts) {
    AppendPolygon(l.belts, BeltCorners(b));
    l.footprints.push_back(BeltCorners(b));
  }
  // A solid outside `within` is left out (neither drawn nor in the legend).
  const auto add = [&](SolidLayer& layer, const models::Solid& solid, double dx, double dy) {
    const auto corners = Footprint(solid, dx, dy);
    if (within != nullptr) {
      Bounds box;
      for (const Point& c : corners) box.Add(c.x, c.y);
      if (box.x_max < within->x_min || box.x_min > within->x_max || box.y_max < within->y_min ||
          box.y_min > within->y_max) {
        return;
      }
    }
    AppendSolid(layer, solid, dx, dy);
    l.footprints.push_back(corners);
  };
  if (obstacles_too) {
    for (const models::Obstacle& o : scene.obstacles) add(l.obstacles, o.solid, 0.0, 0.0);
  }
  for (const models::CarriedObject& c : scene.carried) {
    const auto b = static_cast<std::size_t>(c.belt);
    if (b >= scene.belts.size()) continue;
    const double d = b < travel.size() && travel[b] ? *travel[b] : 0.0;
    if (b < travel.size() && !travel[b]) continue;  // no travel known at that time
    const auto range = models::CarriedTravelRange(scene.belts[b].area, c.solid);
    if (d < range[0] || d > range[1]) continue;
    const double heading = scene.belts[b].area.direction_rad;
    add(l.carried, c.solid, d * std::cos(heading), d * std::sin(heading));
  }
  return l;
}

// The items that draw a layer of solids, one legend entry for the kind
// whether boxes or circles draw it.
void SolidItems(std::vector<PlotItem>& items, const SolidLayer& layer, const std::string& block,
                const std::string& fill, const std::string& title) {
  if (!layer.polygons.empty()) {
    items.push_back(
        {"$" + block + " using 1:2", "with filledcurves closed " + fill + " noautoscale", title});
  }
  if (!layer.circles.empty()) {
    items.push_back({"$" + block + "_circles using 1:2:3", "with circles " + fill + " noautoscale",
                     layer.polygons.empty() ? title : ""});
  }
}

void SolidBlocks(std::string& s, const SolidLayer& layer, const std::string& block) {
  if (!layer.polygons.empty()) AppendBlock(s, block, layer.polygons);
  if (!layer.circles.empty()) AppendBlock(s, block + "_circles", layer.circles);
}

// Row indices of `count` instants evenly spaced from the first row to the
// last (rounded to the nearest row).
std::vector<std::size_t> EvenlySpaced(std::size_t rows, int count) {
  std::vector<std::size_t> picks;
  if (count <= 0) return picks;
  if (count == 1) return {0};
  for (int i = 0; i < count; ++i) {
    const double at = static_cast<double>(i) * static_cast<double>(rows - 1) / (count - 1);
    const auto row = static_cast<std::size_t>(std::lround(at));
    if (picks.empty() || picks.back() != row) picks.push_back(row);
  }
  return picks;
}

// At most about 1,000 points a track (the last one kept): at the usual
// 100 Hz recording a 10 s stretch stays whole, and a robot at 1 m/s moves
// 1 cm between points.
std::string TrackBlock(const std::vector<Point>& track) {
  std::string block;
  if (track.empty()) return block;
  const std::size_t step = (track.size() + 999) / 1000;
  for (std::size_t i = 0; i < track.size(); i += step) {
    block += Num(track[i].x) + "," + Num(track[i].y) + "\n";
  }
  if ((track.size() - 1) % step != 0)
    block += Num(track.back().x) + "," + Num(track.back().y) + "\n";
  return block;
}

// A view's x and y ranges: `view` with a margin, widened to the aspect of
// the plot area so that an equal-scale view fills it.
struct Frame {
  double x0, x1, y0, y1;
  double MetresPerPx(double area_width_px) const { return (x1 - x0) / area_width_px; }
};
Frame FrameOf(const Bounds& view, double area_w_px, double area_h_px, double margin_m) {
  const double aspect = area_w_px / area_h_px;
  double half_x = 0.5 * (view.x_max - view.x_min) + margin_m;
  double half_y = 0.5 * (view.y_max - view.y_min) + margin_m;
  half_x = std::max(half_x, half_y * aspect);
  half_y = std::max(half_y, half_x / aspect);
  const double cx = 0.5 * (view.x_min + view.x_max), cy = 0.5 * (view.y_min + view.y_max);
  return {cx - half_x, cx + half_x, cy - half_y, cy + half_y};
}

std::string FrameLines(const Frame& f) {
  return "set xrange [" + Num(f.x0) + ":" + Num(f.x1) + "]\nset yrange [" + Num(f.y0) + ":" +
         Num(f.y1) + "]\n";
}

// A view's layout: the legend band at the foot, the plot area above it up
// to the caption, and the range that fills the area at equal scale.
struct ViewLayout {
  std::string lines;
  Frame frame;
  double area_w_px;
};
ViewLayout LayoutView(const std::vector<std::string>& titles, const Bounds& view, double margin_m) {
  const style::KeyBand key = style::KeyBelow(titles, kCanvas);
  const double bottom = style::AxisBottomAbove(key.top_screen, kCanvas);
  const double w = (kRight - kLeft) * kCanvas.width_px, h = (kTop - bottom) * kCanvas.height_px;
  const Frame frame = FrameOf(view, w, h, margin_m);
  const style::Panel area{kLeft, kRight, bottom, kTop};
  return {key.commands + area.Margins() +
              "set size ratio -1\nset xlabel 'x (m)'\n"
              "set ylabel 'y (m)'\n" +
              FrameLines(frame),
          frame, w};
}

// A label's box in the map (m), its text centred on (x, y).
struct LabelBox {
  double x, y, half_w, half_h;
  bool Overlaps(const LabelBox& o) const {
    return std::abs(x - o.x) < half_w + o.half_w && std::abs(y - o.y) < half_h + o.half_h;
  }
};

// The time labels of the robot's outlines: instants where the robot stood
// (within a quarter body length of an earlier labelled one) join that
// label ("t = 0 / 6 / 12 s"); each label goes above its outline, else
// below, right or left of it, where it overlaps no other label and stays
// in the frame, and where it covers no outline (`outlines`: their boxes)
// if it can. Returns the $labels rows ("x,y,text").
std::string PlaceTimeLabels(const std::vector<std::pair<Point, double>>& instants,
                            const std::vector<LabelBox>& own, double join_m, const Frame& frame,
                            double metres_per_px, const std::vector<LabelBox>& outlines) {
  struct Group {
    Point at;
    LabelBox outline;
    std::string times;
  };
  std::vector<Group> groups;
  for (std::size_t i = 0; i < instants.size(); ++i) {
    // Not a structured binding: clang 14 cannot capture one in a lambda.
    const Point& at = instants[i].first;
    const double t = instants[i].second;
    auto it = std::find_if(groups.begin(), groups.end(), [&](const Group& g) {
      return std::hypot(at.x - g.at.x, at.y - g.at.y) < join_m;
    });
    if (it != groups.end()) {
      it->times += " / " + style::Short(t, 4);
    } else {
      groups.push_back({at, own[i], style::Short(t, 4)});
    }
  }
  std::vector<LabelBox> placed;
  std::string rows;
  const double pad_px = 3.0;
  for (const Group& g : groups) {
    const std::string text = "t = " + g.times + " s";
    const double half_w =
        0.5 * (style::TextWidthEm(text) * style::kSmallFontPx + 2 * pad_px) * metres_per_px;
    const double half_h = 0.5 * (1.0 * style::kSmallFontPx + 2 * pad_px) * metres_per_px;
    // Beside the outline's box, a pad away.
    const LabelBox& b = g.outline;
    const double gap = pad_px * metres_per_px;
    const LabelBox candidates[] = {{b.x, b.y + b.half_h + gap + half_h, half_w, half_h},
                                   {b.x, b.y - b.half_h - gap - half_h, half_w, half_h},
                                   {b.x + b.half_w + gap + half_w, b.y, half_w, half_h},
                                   {b.x - b.half_w - gap - half_w, b.y, half_w, half_h}};
    const auto clear_of = [&](const LabelBox& b, const std::vector<LabelBox>& boxes) {
      return std::none_of(boxes.begin(), boxes.end(),
                          [&](const LabelBox& p) { return p.Overlaps(b); });
    };
    const auto fits = [&](const LabelBox& b) {
      return b.x - b.half_w >= frame.x0 && b.x + b.half_w <= frame.x1 &&
             b.y - b.half_h >= frame.y0 && b.y + b.half_h <= frame.y1 && clear_of(b, placed);
    };
    const LabelBox* chosen = nullptr;
    for (const bool strict : {true, false}) {
      for (const LabelBox& c : candidates) {
        if (!chosen && fits(c) && (!strict || clear_of(c, outlines))) chosen = &c;
      }
    }
    // Nowhere free: stacked above the highest label it would overlap.
    LabelBox box = chosen ? *chosen : candidates[0];
    while (!chosen && !fits(box) && box.y + box.half_h < frame.y1) box.y += 2.0 * box.half_h;
    placed.push_back(box);
    rows += Num(box.x) + "," + Num(box.y) + "," + text + "\n";
  }
  return rows;
}

// The outlines, wheel contacts and time labels of the top view.
struct Outlines {
  std::string own, contacts;
  std::vector<std::string> others;                 // per other robot
  std::vector<LabelBox> boxes;                     // every outline's bounding box
  std::vector<LabelBox> own_boxes;                 // the robot's, one per instant
  std::vector<std::pair<Point, double>> instants;  // the robot's centre, time
};
// The bounding box of an outline's corners.
LabelBox BoxOf(const std::array<Point, 4>& corners) {
  Bounds b;
  for (const Point& p : corners) b.Add(p.x, p.y);
  return {0.5 * (b.x_min + b.x_max), 0.5 * (b.y_min + b.y_max), 0.5 * (b.x_max - b.x_min),
          0.5 * (b.y_max - b.y_min)};
}

Outlines ReadOutlines(RobotRun& run, Bounds& view) {
  Outlines o;
  const RobotPlotSpec& spec = run.spec;
  const Columns& c = run.col;
  if (c.yaw == 0) return o;
  o.others.assign(c.others.size(), {});
  std::vector<std::string_view> fields;
  std::string line;
  for (std::size_t row : EvenlySpaced(run.signals.row_starts.size(), spec.footprint_count)) {
    table::ReadRow(run.signals, row, line, fields);
    const auto get = [&](int col) { return Column(fields, col); };
    const auto t = get(1), x = get(c.x), y = get(c.y), yaw = get(c.yaw);
    if (!x || !y || !yaw) continue;
    const auto corners = Rectangle(*x, *y, *yaw, spec.body_length_m, spec.body_width_m);
    for (const Point& p : corners) view.Add(p.x, p.y);
    o.boxes.push_back(BoxOf(corners));
    AppendOutline(o.own, *x, *y, *yaw, spec.body_length_m, spec.body_width_m);
    if (t) {
      o.instants.push_back({{*x, *y}, *t});
      o.own_boxes.push_back(BoxOf(corners));
    }
    for (std::size_t k = 0; k < c.others.size(); ++k) {
      const auto ox = get(c.others[k].x), oy = get(c.others[k].y), oyaw = get(c.others[k].yaw);
      if (!ox || !oy || !oyaw) continue;
      const auto& other = spec.others[k];
      const auto corners = Rectangle(*ox, *oy, *oyaw, other.body_length_m, other.body_width_m);
      for (const Point& p : corners) view.Add(p.x, p.y);
      o.boxes.push_back(BoxOf(corners));
      AppendOutline(o.others[k], *ox, *oy, *oyaw, other.body_length_m, other.body_width_m);
    }
    for (const auto& [wx, wy] : c.wheels) {
      const auto px = get(wx), py = get(wy);
      if (px && py) {
        o.contacts += Num(*px) + "," + Num(*py) + "\n";
        view.Add(*px, *py);
      }
    }
  }
  return o;
}

// The frame of the top view: the robot's neighbourhood and the parts of
// the scene within near_m of it (a wall along the path shows, not the
// whole hall); or, when asked, the whole scene.
void FrameScene(const RobotPlotSpec& spec, const SceneLayers& scene,
                const std::vector<std::array<Point, 4>>& end_footprints, Bounds& view) {
  std::vector<std::array<Point, 4>> all = scene.footprints;
  all.insert(all.end(), end_footprints.begin(), end_footprints.end());
  if (spec.whole_scene) {
    const models::Floor& f = spec.scene.floor;
    // A floor as large as models::OpenFloor()'s is unbounded: not framed.
    if (std::max({std::abs(f.min_x_m), std::abs(f.max_x_m), std::abs(f.min_y_m),
                  std::abs(f.max_y_m)}) < 1e5) {
      view.Add(f.min_x_m, f.min_y_m);
      view.Add(f.max_x_m, f.max_y_m);
    }
    for (const auto& corners : all) {
      for (const Point& c : corners) view.Add(c.x, c.y);
    }
    return;
  }
  if (view.empty()) return;
  const Bounds near{view.x_min - spec.near_m, view.x_max + spec.near_m, view.y_min - spec.near_m,
                    view.y_max + spec.near_m};
  for (const auto& corners : all) {
    Bounds box;
    for (const Point& c : corners) box.Add(c.x, c.y);
    const double x0 = std::max(box.x_min, near.x_min), x1 = std::min(box.x_max, near.x_max);
    const double y0 = std::max(box.y_min, near.y_min), y1 = std::min(box.y_max, near.y_max);
    if (x0 > x1 || y0 > y1) continue;
    view.Add(x0, y0);
    view.Add(x1, y1);
  }
}

// Arrows about every metre along each belt's centre line, showing the
// direction of its motion.
std::string BeltArrows(const models::Scene& scene) {
  std::string arrows;
  for (const models::Belt& belt : scene.belts) {
    const models::Rect& b = belt.area;
    const double c = std::cos(b.direction_rad), sn = std::sin(b.direction_rad);
    const int n = std::clamp(static_cast<int>(b.length_m), 1, 200);
    for (int k = 0; k < n; ++k) {
      const double along_m = (k + 0.5) * b.length_m / n - 0.5 * b.length_m - 0.15;
      arrows += Num(b.center_x_m + c * along_m) + "," + Num(b.center_y_m + sn * along_m) + "," +
                Num(0.3 * c) + "," + Num(0.3 * sn) + "\n";
    }
  }
  return arrows;
}

// A fleet's other robot's colour and a worker's: by the robot's place in
// the fleet and the worker's after all robots, so that each has the same
// colour in every robot's figures (the robot's own track and outline have
// theirs, SeriesColour 0 and 1).
const char* OtherColour(const RobotPlotSpec& spec, std::size_t k) {
  return style::SeriesColour(2 + spec.others[k].fleet_index);
}
const char* WorkerColour(const RobotPlotSpec& spec, std::size_t k) {
  return style::SeriesColour(2 + spec.others.size() + 1 + k);
}

// The top view's items over the scene's: the path, the robot, the other
// robots and the workers, each named.
void MovingItems(const RobotRun& run, const Outlines& o, std::vector<PlotItem>& items) {
  const RobotPlotSpec& spec = run.spec;
  if (spec.path_m.size() == 1) {
    items.push_back(
        {"$path using 1:2", "with points pt 3 ps 3 lw 2 lc rgb '#000000'", "hold target"});
  } else if (!spec.path_m.empty()) {
    items.push_back(
        {"$path using 1:2", std::string("with lines ") + style::kDesiredPathStyle, "desired path"});
  }
  const std::string own = spec.others.empty() ? "robot" : spec.robot_name;
  items.push_back({"$signals using " + std::to_string(run.data[run.col.x]) + ":" +
                       std::to_string(run.data[run.col.y]),
                   std::string("with lines ") + style::kTrackStyle, own + ": actual path"});
  if (!o.own.empty()) {
    items.push_back({"$outlines using 1:2", std::string("with lines ") + style::kOutlineStyle,
                     own + ": outline at the labelled times"});
  }
  // Other robots and workers: a colour each, the same in every robot's
  // figures, after the robot's own two.
  for (std::size_t k = 0; k < spec.others.size(); ++k) {
    if (run.other_tracks[k].empty()) continue;
    const std::string lc = std::string(" lc rgb '") + OtherColour(spec, k) + "'";
    items.push_back({"$other_track_" + std::to_string(k) + " using 1:2", "with lines lw 2" + lc,
                     spec.others[k].name + ": path and outlines"});
    if (k < o.others.size() && !o.others[k].empty()) {
      items.push_back(
          {"$other_outlines_" + std::to_string(k) + " using 1:2", "with lines lw 1" + lc, ""});
    }
  }
  for (std::size_t k = 0; k < spec.workers.size(); ++k) {
    if (run.worker_tracks[k].empty()) continue;
    items.push_back({"$worker_track_" + std::to_string(k) + " using 1:2",
                     std::string("with lines lw 2 dt 3 lc rgb '") + WorkerColour(spec, k) + "'",
                     spec.workers[k].name + ": walk"});
  }
  if (!o.contacts.empty()) {
    items.push_back({"$contacts using 1:2", std::string("with points ") + style::kContactStyle,
                     "wheel contacts"});
  }
}

}  // namespace

std::array<Point, 4> Rectangle(double x, double y, double yaw, double length, double width) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double hl = 0.5 * length, hw = 0.5 * width;
  std::array<Point, 4> corners;
  const double sx[4] = {hl, -hl, -hl, hl}, sy[4] = {hw, hw, -hw, -hw};
  for (int k = 0; k < 4; ++k) {
    corners[k] = {x + c * sx[k] - s * sy[k], y + s * sx[k] + c * sy[k]};
  }
  return corners;
}

// top_view.png: the scene near the path (belts with their motion,
// obstacles, carried objects at the start and at the end), the desired and
// actual paths, the robot's outline and wheel contacts at a few labelled
// instants, a fleet's other robots and the workers.
std::string TopView(RobotRun& run) {
  const RobotPlotSpec& spec = run.spec;
  Bounds view = run.tracks;
  const Outlines o = ReadOutlines(run, view);
  {
    const SceneLayers all = SceneAt(spec.scene, {}, true);
    const SceneLayers all_end =
        run.travel_end.empty() ? SceneLayers{} : SceneAt(spec.scene, run.travel_end, false);
    FrameScene(spec, all, all_end.footprints, view);
  }
  // What is in the frame: solids outside it are not listed in the legend.
  const SceneLayers start = SceneAt(spec.scene, {}, true, &view);
  const SceneLayers end =
      run.travel_end.empty() ? SceneLayers{} : SceneAt(spec.scene, run.travel_end, false, &view);

  std::string s;
  if (!start.belts.empty()) AppendBlock(s, "belts", start.belts);
  const std::string arrows = BeltArrows(spec.scene);
  if (!arrows.empty()) AppendBlock(s, "belt_direction", arrows);
  SolidBlocks(s, start.obstacles, "obstacles");
  SolidBlocks(s, start.carried, "carried");
  SolidBlocks(s, end.carried, "carried_end");
  std::string path;
  for (const auto& p : spec.path_m) path += Num(p[0]) + "," + Num(p[1]) + "\n";
  if (!path.empty()) AppendBlock(s, "path", path);
  if (!o.own.empty()) AppendBlock(s, "outlines", o.own);
  for (std::size_t k = 0; k < o.others.size(); ++k) {
    if (!o.others[k].empty()) AppendBlock(s, "other_outlines_" + std::to_string(k), o.others[k]);
  }
  for (std::size_t k = 0; k < run.other_tracks.size(); ++k) {
    if (!run.other_tracks[k].empty()) {
      AppendBlock(s, "other_track_" + std::to_string(k), TrackBlock(run.other_tracks[k]));
    }
  }
  for (std::size_t k = 0; k < run.worker_tracks.size(); ++k) {
    if (!run.worker_tracks[k].empty()) {
      AppendBlock(s, "worker_track_" + std::to_string(k), TrackBlock(run.worker_tracks[k]));
    }
  }
  if (!o.contacts.empty()) AppendBlock(s, "contacts", o.contacts);

  std::vector<PlotItem> items;
  if (!start.belts.empty()) {
    items.push_back({"$belts using 1:2",
                     std::string("with filledcurves closed ") + style::kBeltFill + " noautoscale",
                     "belt"});
    items.push_back({"$belt_direction using 1:2:3:4",
                     std::string("with vectors ") + style::kBeltArrow + " noautoscale",
                     "belt's motion"});
  }
  SolidItems(items, start.obstacles, "obstacles", style::kObstacleFill, "obstacle");
  SolidItems(items, start.carried, "carried", style::kCarriedFill, "carried object (t = 0)");
  if (!end.carried.polygons.empty()) {
    items.push_back({"$carried_end using 1:2",
                     std::string("with lines ") + style::kCarriedEndStyle + " noautoscale",
                     "carried object (end)"});
  }
  if (!end.carried.circles.empty()) {
    items.push_back({"$carried_end_circles using 1:2:3",
                     "with circles fillstyle empty border lc rgb '#C07020' noautoscale",
                     end.carried.polygons.empty() ? "carried object (end)" : ""});
  }
  MovingItems(run, o, items);

  const double margin_m = 0.3 + 0.05 * std::max(view.x_max - view.x_min, view.y_max - view.y_min);
  const ViewLayout layout = LayoutView(style::Titles(items), view, view.empty() ? 1.0 : margin_m);
  if (!o.instants.empty()) {
    const std::string labels =
        PlaceTimeLabels(o.instants, o.own_boxes, 0.25 * spec.body_length_m, layout.frame,
                        layout.frame.MetresPerPx(layout.area_w_px), o.boxes);
    AppendBlock(s, "labels", labels);
    items.push_back(
        {"$labels using 1:2:3",
         "with labels boxed font '," + style::Short(style::kSmallFontPx * 0.75, 3) + "'", ""});
  }
  const std::string what = spec.whole_scene ? "Top view of the scene (map frame)"
                                            : "Top view of the robot's path (map frame)";
  return "\n" + s + style::BeginFigure(spec.file_prefix + "top_view", spec.format, run.outputs) +
         style::Caption(what, spec.run_caption) + layout.lines + style::PlotCommand(items);
}

namespace {

// The other robots (outlines) and the workers (torso and legs) in a scan
// view, from the row `fields` of the scan's start: their blocks appended
// to `s`, their items to `items`.
void ScanMovers(const RobotPlotSpec& spec, const Columns& c,
                const std::vector<std::string_view>& fields, std::string& s,
                std::vector<PlotItem>& items) {
  for (std::size_t k = 0; k < c.others.size(); ++k) {
    const auto ox = Column(fields, c.others[k].x), oy = Column(fields, c.others[k].y),
               oyaw = Column(fields, c.others[k].yaw);
    if (!ox || !oy || !oyaw) continue;
    std::string block;
    AppendOutline(block, *ox, *oy, *oyaw, spec.others[k].body_length_m,
                  spec.others[k].body_width_m);
    AppendBlock(s, "scan_other_" + std::to_string(k), block);
    items.push_back({"$scan_other_" + std::to_string(k) + " using 1:2",
                     std::string("with lines lw 2 lc rgb '") + OtherColour(spec, k) + "'",
                     spec.others[k].name});
  }
  for (std::size_t k = 0; k < c.workers.size(); ++k) {
    const RobotPlotSpec::Worker& w = spec.workers[k];
    const auto wx = Column(fields, c.workers[k].x), wy = Column(fields, c.workers[k].y);
    if (!wx || !wy) continue;
    std::string block = Num(*wx) + "," + Num(*wy) + "," + Num(w.torso_radius_m) + "\n";
    const auto lx = Column(fields, c.workers[k].legs[0]), ly = Column(fields, c.workers[k].legs[1]);
    const auto rx = Column(fields, c.workers[k].legs[2]), ry = Column(fields, c.workers[k].legs[3]);
    if (lx && ly && rx && ry) {
      block += Num(*lx) + "," + Num(*ly) + "," + Num(w.leg_radius_m) + "\n" + Num(*rx) + "," +
               Num(*ry) + "," + Num(w.leg_radius_m) + "\n";
    }
    AppendBlock(s, "scan_worker_" + std::to_string(k), block);
    items.push_back(
        {"$scan_worker_" + std::to_string(k) + " using 1:2:3",
         std::string("with circles lw 1.5 lc rgb '") + WorkerColour(spec, k) + "' fillstyle empty",
         w.name + " (torso, legs)"});
  }
}

}  // namespace

// scan.png: the scan the scanner had completed at spec.scan.time_s, its
// rays and hits drawn from the robot's pose at the scan's start, over the
// scene as it was then: the carried objects where the belts had moved
// them, the other robots and the workers' legs and torsos.
std::string ScanView(RobotRun& run) {
  const RobotPlotSpec& spec = run.spec;
  const RobotPlotSpec::Scan& scan = spec.scan;
  const Columns& c = run.col;
  if (c.ranges.empty()) return {};
  std::string line;
  std::vector<std::string_view> fields;
  table::ReadRow(run.signals, table::RowAt(run.signals, scan.time_s), line, fields);
  std::vector<double> range(c.ranges.size(), scan.no_return_m);
  for (std::size_t k = 0; k < c.ranges.size(); ++k) {
    if (const auto r = Column(fields, c.ranges[k])) range[k] = *r;
  }
  const auto started = Column(fields, c.scan_time);
  const double start_s = started ? *started : scan.time_s;
  table::ReadRow(run.signals, table::RowAt(run.signals, start_s), line, fields);
  const auto x = Column(fields, c.x), y = Column(fields, c.y), yaw = Column(fields, c.yaw);
  if (!x || !y || !yaw) throw std::runtime_error("no robot pose at the scan's start time");
  std::vector<std::optional<double>> travel(c.belt_travels.size());
  for (std::size_t b = 0; b < c.belt_travels.size(); ++b) {
    travel[b] = Column(fields, c.belt_travels[b]);
    if (!travel[b]) travel[b] = 0.0;
  }

  const double cy = std::cos(*yaw), sy = std::sin(*yaw);
  const double sx = *x + cy * scan.mount_x_m - sy * scan.mount_y_m;
  const double sy2 = *y + sy * scan.mount_x_m + cy * scan.mount_y_m;
  std::string rays, hits;
  Bounds view;
  view.Add(sx, sy2);
  for (std::size_t k = 0; k < range.size(); ++k) {
    if (!(range[k] != scan.no_return_m) || !std::isfinite(range[k])) continue;
    const double a = *yaw + scan.mount_yaw_rad + scan.first_beam_rad +
                     static_cast<double>(k) * scan.beam_step_rad;
    const double hx = sx + range[k] * std::cos(a), hy = sy2 + range[k] * std::sin(a);
    hits += Num(hx) + "," + Num(hy) + "\n";
    if (k % 4 == 0) rays += Num(sx) + "," + Num(sy2) + "\n" + Num(hx) + "," + Num(hy) + "\n\n";
    view.Add(hx, hy);
  }
  const SceneLayers scene = SceneAt(spec.scene, travel, true);
  std::string outline;
  AppendOutline(outline, *x, *y, *yaw, spec.body_length_m, spec.body_width_m);

  std::string s;
  AppendBlock(s, "scan_rays", rays.empty() ? "\n" : rays);
  AppendBlock(s, "scan_hits", hits.empty() ? "nan,nan\n" : hits);
  AppendBlock(s, "scan_outline", outline);
  if (!scene.belts.empty()) AppendBlock(s, "scan_belts", scene.belts);
  SolidBlocks(s, scene.obstacles, "scan_obstacles");
  SolidBlocks(s, scene.carried, "scan_carried");
  std::vector<PlotItem> items;
  if (!scene.belts.empty()) {
    items.push_back({"$scan_belts using 1:2",
                     std::string("with filledcurves closed ") + style::kBeltFill, "belt"});
  }
  SolidItems(items, scene.obstacles, "scan_obstacles", style::kObstacleFill, "obstacle");
  SolidItems(items, scene.carried, "scan_carried", style::kCarriedFill, "carried object (then)");
  ScanMovers(spec, c, fields, s, items);
  items.push_back(
      {"$scan_rays using 1:2", "with lines lw 0.5 lc rgb '#9ECAE1'", "rays (every 4th)"});
  items.push_back({"$scan_hits using 1:2", "with points pt 7 ps 0.35 lc rgb '#D55E00'", "hits"});
  items.push_back({"$scan_outline using 1:2", std::string("with lines ") + style::kOutlineStyle,
                   spec.robot_name.empty() ? "robot" : spec.robot_name});
  const ViewLayout layout = LayoutView(style::Titles(items), view, 1.0);
  return "\n" + s + style::BeginFigure(spec.file_prefix + "scan", spec.format, run.outputs) +
         style::Caption("One scan of " + scan.sensor +
                            ", started at t = " + style::Short(start_s, 4) + " s (" +
                            std::to_string(range.size()) + " beams)",
                        spec.run_caption) +
         layout.lines + style::PlotCommand(items);
}

namespace {

// The highest terrain piece under map point (x, y) and its top's height;
// the floor (-1, 0) where there is none.
std::pair<int, double> GroundAt(const models::Scene& scene, double x, double y) {
  std::pair<int, double> ground{-1, 0.0};
  for (std::size_t i = 0; i < scene.terrain.size(); ++i) {
    const auto top = models::TerrainTopAt(scene.terrain[i], x, y);
    if (top && *top >= ground.second) ground = {static_cast<int>(i), *top};
  }
  return ground;
}

}  // namespace

// side_view.png: base_link's height and the ground under it against the
// distance travelled in the plane, each stretch of ground named.
std::string SideView(RobotRun& run) {
  const RobotPlotSpec& spec = run.spec;
  const Columns& c = run.col;
  if (c.z == 0) return {};
  std::string data;
  std::vector<std::string_view> fields;
  std::string line;
  double travelled_m = 0.0, top_m = 0.0;
  std::optional<Point> last;
  // Stretches of one piece of ground: where each begins and ends.
  struct Stretch {
    int piece;
    double from_m, to_m, height_m;
  };
  std::vector<Stretch> stretches;
  for (std::size_t row = 0; row < run.signals.row_starts.size(); ++row) {
    table::ReadRow(run.signals, row, line, fields);
    const auto x = Column(fields, c.x), y = Column(fields, c.y), z = Column(fields, c.z);
    if (!x || !y || !z) continue;
    if (last) travelled_m += std::hypot(*x - last->x, *y - last->y);
    last = Point{*x, *y};
    const auto [piece, ground] = GroundAt(spec.scene, *x, *y);
    top_m = std::max({top_m, *z, ground});
    data += Num(travelled_m) + "," + Num(*z) + "," + Num(ground) + "\n";
    if (stretches.empty() || stretches.back().piece != piece) {
      stretches.push_back({piece, travelled_m, travelled_m, ground});
    }
    stretches.back().to_m = travelled_m;
    stretches.back().height_m = std::max(stretches.back().height_m, ground);
  }
  if (data.empty()) return {};
  std::string s;
  AppendBlock(s, "side", data);
  // Each stretch of ground named under it, below the floor's level.
  std::string names;
  for (const Stretch& st : stretches) {
    if (st.to_m - st.from_m < 0.02 * travelled_m) continue;  // too short to name
    std::string name = "floor";
    if (st.piece >= 0) {
      name = spec.scene.terrain[static_cast<std::size_t>(st.piece)].name;
      if (name.empty()) name = "terrain piece " + std::to_string(st.piece);
    }
    names += Num(0.5 * (st.from_m + st.to_m)) + "," + Num(-0.05 * std::max(top_m, 0.1)) + "," +
             name + "\n";
  }
  if (!names.empty()) AppendBlock(s, "ground_names", names);
  std::vector<PlotItem> items = {
      {"$side using 1:3", "with filledcurves y1=0 fillcolor rgb '#C8C8C8' fillstyle solid 1.0",
       "ground under the track"},
      {"$side using 1:2", std::string("with lines ") + style::kTrackStyle,
       "robot: base_link's height"}};
  if (!names.empty()) {
    items.push_back({"$ground_names using 1:2:3", "with labels boxed", ""});
  }
  const style::KeyBand key = style::KeyBelow(style::Titles(items), kCanvas);
  return "\n" + s + style::BeginFigure(spec.file_prefix + "side_view", spec.format, run.outputs) +
         style::Caption("Side view: the robot's height along its track", spec.run_caption) +
         key.commands + "set bmargin at screen " +
         style::Short(style::AxisBottomAbove(key.top_screen, kCanvas), 4) +
         "\nset xlabel 'distance travelled in the plane (m)'\nset ylabel 'height (m)'\n"
         "set xrange [0:" +
         Num(travelled_m) + "]\nset yrange [" + Num(-0.1 * std::max(top_m, 0.1)) + ":" +
         Num(1.2 * std::max(top_m, 0.1)) + "]\n" + style::PlotCommand(items);
}

}  // namespace linesim::plots::robot
