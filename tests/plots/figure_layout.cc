#include "figure_layout.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <regex>
#include <sstream>

#include "plots/figure_style.h"
#include "plots/gnuplot.h"

namespace linesim::plots::layout {

namespace {

namespace fs = std::filesystem;

std::string ReadAll(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string Quoted(const std::string& line) {
  const auto a = line.find('\''), b = line.rfind('\'');
  return a == std::string::npos || b <= a ? std::string() : line.substr(a + 1, b - a - 1);
}

std::string SvgName(const std::string& picture) {
  return "layout_" + fs::path(picture).stem().string() + ".svg";
}

// The script drawn again on the SVG terminal as the PNG lays out (the
// canvas size of its first terminal line, 13.33 px text), each picture as
// layout_NAME.svg, and a line "AREA NAME xmin xmax ymin ymax" (px from the
// bottom left) printed to layout_areas.txt after every plot command.
std::string Instrument(const std::string& script) {
  static const std::regex kSize(R"(size (\d+),(\d+))");
  std::smatch size;
  if (!std::regex_search(script, size, kSize)) {
    ADD_FAILURE() << "no terminal size in the script";
    return {};
  }
  std::string out = "set print 'layout_areas.txt'\n";
  bool terminal_set = false, in_data = false, in_plot = false;
  std::string picture;
  for (const std::string& line : Lines(script)) {
    if (in_data) {
      out += line + "\n";
      in_data = line != "EOD";
      continue;
    }
    if (line.find("<< EOD") != std::string::npos) {
      in_data = true;
      out += line + "\n";
      continue;
    }
    if (line.rfind("set output", 0) == 0) {
      if (!terminal_set) {
        out += "set terminal svg size " + size[1].str() + "," + size[2].str() +
               " noenhanced font '," + style::Short(style::kFontPx, 4) +
               "' mouse background rgb 'white'\n";
        terminal_set = true;
      }
      picture = Quoted(line);
      out += "set output '" + SvgName(picture) + "'\n";
      continue;
    }
    out += line + "\n";
    const bool starts = line.rfind("plot ", 0) == 0;
    if (starts) in_plot = true;
    if (in_plot && (line.empty() || line.back() != '\\')) {
      in_plot = false;
      out += "print sprintf('AREA %s %g %g %g %g', '" + SvgName(picture) +
             "', GPVAL_TERM_XMIN, GPVAL_TERM_XMAX, GPVAL_TERM_YMIN, GPVAL_TERM_YMAX)\n";
    }
  }
  return out + "unset output\n";
}

std::string Decode(std::string text) {
  static const std::pair<const char*, const char*> kEntities[] = {
      {"&apos;", "'"}, {"&quot;", "\""}, {"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}};
  for (const auto& [entity, plain] : kEntities) {
    for (auto at = text.find(entity); at != std::string::npos; at = text.find(entity, at + 1)) {
      text.replace(at, std::string(entity).size(), plain);
    }
  }
  return text;
}

std::string Attribute(const std::string& tag, const std::string& name) {
  for (const char quote : {'"', '\''}) {
    const std::string key = name + "=" + quote;
    auto at = tag.find(key);
    if (at == std::string::npos) {
      const std::string spaced = name + " = " + quote;
      at = tag.find(spaced);
      if (at == std::string::npos) continue;
      at += spaced.size();
    } else {
      at += key.size();
    }
    return tag.substr(at, tag.find(quote, at) - at);
  }
  return {};
}

std::vector<double> Numbers(const std::string& text) {
  std::vector<double> out;
  const char* p = text.c_str();
  while (*p) {
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end != p) {
      out.push_back(v);
      p = end;
    } else {
      ++p;
    }
  }
  return out;
}

// The box of a text drawn at the translate/rotate of `group` with its
// font size and anchor.
Box TextBox(const std::string& group, const std::string& text) {
  const std::vector<double> at = Numbers(group.substr(group.find("translate(")));
  const double size = std::stod(Attribute(group, "font-size"));
  const std::string anchor = Attribute(group, "text-anchor");
  const double w = style::TextWidthEm(text) * size;
  double a0 = 0.0;  // along the text, from the anchor
  if (anchor == "middle") a0 = -0.5 * w;
  if (anchor == "end") a0 = -w;
  const double up = style::kAscentEm * size, down = style::kDescentEm * size;
  const bool rotated = group.find("rotate(270)") != std::string::npos ||
                       group.find("rotate(-90)") != std::string::npos;
  if (rotated) return {at[0] - up, at[1] - a0 - w, at[0] + down, at[1] - a0};
  return {at[0] + a0, at[1] - up, at[0] + a0 + w, at[1] + down};
}

// The bounding box of a drawn shape: a path's d, a polygon's points, a
// `use` of a point symbol (translate and scale), a circle.
std::optional<Box> ShapeBox(const std::string& tag) {
  std::vector<double> v;
  if (tag.rfind("<path", 0) == 0) v = Numbers(Attribute(tag, "d"));
  if (tag.rfind("<polygon", 0) == 0) v = Numbers(Attribute(tag, "points"));
  if (tag.rfind("<use", 0) == 0) {
    const std::vector<double> t = Numbers(tag.substr(tag.find("translate(")));
    if (t.size() < 3) return std::nullopt;
    return Box{t[0] - t[2], t[1] - t[2], t[0] + t[2], t[1] + t[2]};
  }
  if (tag.rfind("<circle", 0) == 0) {
    const double cx = std::stod(Attribute(tag, "cx")), cy = std::stod(Attribute(tag, "cy")),
                 r = std::stod(Attribute(tag, "r"));
    return Box{cx - r, cy - r, cx + r, cy + r};
  }
  if (v.size() < 2) return std::nullopt;
  Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
  for (std::size_t i = 0; i + 1 < v.size(); i += 2) {
    b.x0 = std::min(b.x0, v[i]);
    b.x1 = std::max(b.x1, v[i]);
    b.y0 = std::min(b.y0, v[i + 1]);
    b.y1 = std::max(b.y1, v[i + 1]);
  }
  return b;
}

// Reads an SVG of gnuplot's svg terminal (with `mouse`): every text, which
// are legend entries (in a *_keyentry group) and which a plot item drew
// (in a gnuplot_plot_N group), and each legend entry's sample: a shape in
// a keyentry group of its own (points), else the first shape its plot
// group draws after the entry's text (lines, fills). A boxed label is
// drawn twice, its box first (a textbox filter): read once.
void ReadSvg(const std::string& svg, Figure& figure) {
  const auto open = svg.find("<svg");
  figure.width_px = std::stod(Attribute(svg.substr(open, 400), "width"));
  figure.height_px = std::stod(Attribute(svg.substr(open, 400), "height"));
  enum Kind { kOther, kPlot, kKey };
  std::vector<Kind> stack;
  std::string group;   // the last <g ...> tag with a translate
  bool keyed = false;  // the plot group has a legend entry
  std::optional<Box> after_text, in_key;
  const auto inside = [&](Kind k) {
    return std::find(stack.begin(), stack.end(), k) != stack.end();
  };
  const auto end_plot = [&]() {
    if (keyed && (in_key || after_text))
      figure.key_samples.push_back(in_key ? *in_key : *after_text);
    keyed = false;
    after_text.reset();
    in_key.reset();
  };
  for (std::size_t at = svg.find('<', open); at != std::string::npos; at = svg.find('<', at + 1)) {
    const std::size_t end = svg.find('>', at);
    const std::string tag = svg.substr(at, end - at + 1);
    const bool closed = tag[tag.size() - 2] == '/';
    if (tag.rfind("</g", 0) == 0) {
      if (!stack.empty()) {
        const Kind k = stack.back();
        stack.pop_back();
        if (k == kPlot && !inside(kPlot)) end_plot();
      }
    } else if (tag.rfind("<g", 0) == 0) {
      const std::string id = Attribute(tag, "id");
      const Kind kind = id.ends_with("_keyentry")           ? kKey
                        : id.rfind("gnuplot_plot_", 0) == 0 ? kPlot
                                                            : kOther;
      if (tag.find("translate(") != std::string::npos) group = tag;
      if (!closed) stack.push_back(kind);
    } else if (tag == "<text>" && !group.empty()) {
      // gnuplot's texts (the mousing box's own, with attributes, are not
      // the figure's); a boxed label's first drawing is its box.
      const std::size_t close = svg.find("</text>", end);
      if (group.find("filter:url(") == std::string::npos) {
        std::string text = svg.substr(end + 1, close - end - 1);
        static const std::regex kTags("<[^>]*>");
        text = Decode(std::regex_replace(text, kTags, ""));
        Text t{text, TextBox(group, text), inside(kKey), !inside(kKey) && inside(kPlot)};
        keyed = keyed || t.key;
        figure.texts.push_back(t);
      }
      at = close;
    } else if (tag.rfind("<path", 0) == 0 || tag.rfind("<polygon", 0) == 0 ||
               tag.rfind("<use", 0) == 0 || tag.rfind("<circle", 0) == 0) {
      if (keyed && inside(kPlot)) {
        const auto box = ShapeBox(tag);
        if (box && inside(kKey) && !in_key) in_key = box;
        if (box && !after_text) after_text = box;
      }
    } else if ((tag.rfind("<title", 0) == 0 || tag.rfind("<script", 0) == 0) && !closed) {
      at = svg.find(tag.rfind("<title", 0) == 0 ? "</title>" : "</script>", end);
    }
  }
}

std::string Describe(const Box& b) {
  std::ostringstream out;
  out << "[" << std::lround(b.x0) << ".." << std::lround(b.x1) << " x " << std::lround(b.y0) << ".."
      << std::lround(b.y1) << "]";
  return out.str();
}

}  // namespace

bool Box::Overlaps(const Box& o, double tolerance_px) const {
  return std::min(x1, o.x1) - std::max(x0, o.x0) > tolerance_px &&
         std::min(y1, o.y1) - std::max(y0, o.y0) > tolerance_px;
}

bool Box::Inside(const Box& o, double tolerance_px) const {
  return x0 >= o.x0 - tolerance_px && x1 <= o.x1 + tolerance_px && y0 >= o.y0 - tolerance_px &&
         y1 <= o.y1 + tolerance_px;
}

std::vector<Figure> DrawAndRead(const std::string& dir, const std::string& script) {
  const fs::path folder(dir);
  const std::string instrumented = Instrument(ReadAll(folder / script));
  const std::string name = "layout_" + script;
  {
    std::ofstream out(folder / name, std::ios::binary);
    out << instrumented;
  }
  fs::remove(folder / "layout_areas.txt");
  const GnuplotResult run = RunGnuplot(dir, name);
  if (run.exit_status != 0) {
    ADD_FAILURE() << "gnuplot failed on " << name << ": " << run.errors;
    return {};
  }
  std::map<std::string, std::vector<Box>> areas;
  std::vector<std::string> order;
  std::istringstream lines(ReadAll(folder / "layout_areas.txt"));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream in(line);
    std::string tag, file;
    double x0, x1, y0, y1;
    if (!(in >> tag >> file >> x0 >> x1 >> y0 >> y1) || tag != "AREA") continue;
    if (!areas.count(file)) order.push_back(file);
    areas[file].push_back({x0, y0, x1, y1});  // from the bottom: flipped below
  }
  std::vector<Figure> figures;
  for (const std::string& file : order) {
    Figure f;
    f.file = file;
    ReadSvg(ReadAll(folder / file), f);
    for (Box b : areas[file]) {
      f.plot_areas.push_back({b.x0, f.height_px - b.y1, b.x1, f.height_px - b.y0});
    }
    figures.push_back(f);
  }
  return figures;
}

std::vector<std::string> Problems(const Figure& figure) {
  std::vector<std::string> problems;
  const Box canvas{0, 0, figure.width_px, figure.height_px};
  const auto name = [&](const Text& t) {
    return "'" + t.text + "' " + Describe(t.box) + (t.key ? " (legend)" : "");
  };
  for (std::size_t i = 0; i < figure.texts.size(); ++i) {
    const Text& a = figure.texts[i];
    if (a.text.find_first_not_of(' ') == std::string::npos) continue;
    if (!a.box.Inside(canvas)) problems.push_back(name(a) + " is outside the canvas");
    for (std::size_t j = i + 1; j < figure.texts.size(); ++j) {
      const Text& b = figure.texts[j];
      if (b.text.find_first_not_of(' ') == std::string::npos) continue;
      if (a.box.Overlaps(b.box)) problems.push_back(name(a) + " overlaps " + name(b));
    }
    for (const Box& sample : figure.key_samples) {
      if (a.box.Overlaps(sample)) {
        problems.push_back(name(a) + " overlaps a legend sample " + Describe(sample));
      }
    }
    for (const Box& area : figure.plot_areas) {
      if (a.key && a.box.Overlaps(area, 1.0)) {
        problems.push_back(name(a) + " is inside the plot area " + Describe(area));
      }
    }
    if (a.label && std::none_of(figure.plot_areas.begin(), figure.plot_areas.end(),
                                [&](const Box& area) { return a.box.Inside(area, 1.0); })) {
      problems.push_back("label " + name(a) + " is not inside the plot area");
    }
  }
  for (const Box& sample : figure.key_samples) {
    for (const Box& area : figure.plot_areas) {
      if (sample.Overlaps(area, 1.0)) {
        problems.push_back("a legend sample " + Describe(sample) + " is inside the plot area " +
                           Describe(area));
      }
    }
  }
  return problems;
}

}  // namespace linesim::plots::layout
