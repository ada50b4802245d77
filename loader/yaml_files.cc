#include "loader/yaml_files.h"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "config/input_files.h"
#include "cosim/closest_names.h"
#include "models/models_dir.h"

namespace linesim::loader {

namespace fs = std::filesystem;

namespace {

// Sees a document's events and keeps only where it starts (its first node,
// else its start marker): enough to tell whether a file holds a second
// document, and where, without building it.
class DocumentStarts : public YAML::EventHandler {
 public:
  YAML::Mark start = YAML::Mark::null_mark();
  YAML::Mark content = YAML::Mark::null_mark();
  int Line() const {
    const YAML::Mark& m = content.is_null() ? start : content;
    return m.is_null() ? 0 : m.line + 1;
  }
  void OnDocumentStart(const YAML::Mark& mark) override {
    start = mark;
    content = YAML::Mark::null_mark();
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { Node(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { Node(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    Node(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Node(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Node(mark);
  }
  void OnMapEnd() override {}

 private:
  void Node(const YAML::Mark& mark) {
    if (content.is_null()) content = mark;
  }
};

// The first key a map of `node`'s tree gives twice (yaml-cpp keeps both
// pairs and a lookup finds the first, so the second would be silently
// ignored): its text and the lines of both. Nodes reached again through an
// alias (the same position in the file) are scanned once.
struct DuplicateKey {
  std::string key;
  int line = 0, first_line = 0;
};

std::optional<DuplicateKey> FindDuplicateKey(const YAML::Node& node,
                                             std::set<std::size_t>& visited) {
  if (!node.IsMap() && !node.IsSequence()) return std::nullopt;
  const YAML::Mark mark = node.Mark();
  if (!mark.is_null() && !visited.insert(static_cast<std::size_t>(mark.pos)).second) {
    return std::nullopt;
  }
  if (node.IsSequence()) {
    for (const auto& item : node) {
      if (auto d = FindDuplicateKey(item, visited)) return d;
    }
    return std::nullopt;
  }
  std::map<std::string, int> seen;
  for (const auto& kv : node) {
    if (kv.first.IsScalar()) {
      const int line = kv.first.Mark().is_null() ? 0 : kv.first.Mark().line + 1;
      const auto [it, fresh] = seen.emplace(kv.first.Scalar(), line);
      if (!fresh) return DuplicateKey{kv.first.Scalar(), line, it->second};
    }
    if (auto d = FindDuplicateKey(kv.second, visited)) return d;
  }
  return std::nullopt;
}

}  // namespace

YamlFile LoadYamlFile(const std::string& file) {
  YamlFile out;
  std::error_code ec;
  // Every file a scenario reads is recorded where it is read (the record a
  // sweep keeps: config/input_files.h), a missing or unreadable one too: a
  // result refused for its lack is as much the file's doing.
  if (!fs::exists(file, ec)) {
    config::RecordInputFile(file);
    out.problem = YamlFile::Problem::kMissing;
    return out;
  }
  if (!fs::is_regular_file(file, ec)) {
    config::RecordInputFile(file);
    out.problem = YamlFile::Problem::kFolder;
    return out;
  }
  // Checked before reading: yaml-cpp's tree takes some 50 bytes per byte
  // of text (a 40 MB scenario exhausted 2 GB).
  if (const auto size = fs::file_size(file, ec); !ec && size > kMaxYamlBytes) {
    config::RecordInputFile(file);
    out.problem = YamlFile::Problem::kUnreadable;
    out.detail = "it is " + std::to_string(size) + " bytes, more than the " +
                 std::to_string(kMaxYamlBytes >> 20) +
                 " MiB linesim reads from a YAML file (kMaxYamlBytes)";
    return out;
  }
  try {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (!in) {
      config::RecordInputFile(file);
      out.problem = YamlFile::Problem::kUnreadable;
      out.detail = "not readable";
      return out;
    }
    const std::string text = buffer.str();
    config::RecordInput(file, text);
    // A second document (after "---", or after a "..." end marker) would be
    // silently dropped by a single-document read. Asked of the parser one
    // document at a time, at most two: yaml-cpp's LoadAll never ends on text
    // it cannot place in any document (a line starting with ',' yields an
    // empty document forever, growing memory without bound).
    {
      std::istringstream events(text);
      YAML::Parser parser(events);
      DocumentStarts starts;
      if (parser.HandleNextDocument(starts) && parser.HandleNextDocument(starts)) {
        out.problem = YamlFile::Problem::kInvalid;
        out.detail =
            "a second YAML document (after '---' or '...'), or text outside any document: "
            "linesim reads one document per file, so the rest would be ignored";
        out.line = starts.Line();
        return out;
      }
    }
    out.root = YAML::Load(text);
    std::set<std::size_t> visited;
    if (const auto d = FindDuplicateKey(out.root, visited)) {
      out.problem = YamlFile::Problem::kInvalid;
      out.detail = "key '" + d->key + "' appears twice in one map (first at line " +
                   std::to_string(d->first_line) + "): one of them would be ignored";
      out.line = d->line;
      out.root = YAML::Node();
    }
  } catch (const YAML::BadFile&) {
    out.problem = YamlFile::Problem::kUnreadable;
    out.detail = "not readable";
  } catch (const YAML::ParserException& e) {
    out.problem = YamlFile::Problem::kInvalid;
    out.detail = e.msg;
    out.line = e.mark.is_null() ? 0 : e.mark.line + 1;
  } catch (const std::exception& e) {
    out.problem = YamlFile::Problem::kUnreadable;
    out.detail = e.what();
  }
  return out;
}

YAML::Node LoadYamlOrThrow(const std::string& file, const std::string& kind) {
  const std::string what = kind.empty() ? "file" : kind + " file";
  YamlFile loaded = LoadYamlFile(file);
  switch (loaded.problem) {
    case YamlFile::Problem::kNone:
      break;
    case YamlFile::Problem::kMissing:
      throw ScenarioError(
          {{file, 0, "", "cannot read the " + what + " (missing or not readable)"}});
    case YamlFile::Problem::kFolder:
      throw ScenarioError({{file, 0, "", "is not a file (a folder?): expected a YAML " + what}});
    case YamlFile::Problem::kInvalid:
      throw ScenarioError({{file, loaded.line, "", "not valid YAML: " + loaded.detail}});
    case YamlFile::Problem::kUnreadable:
      throw ScenarioError({{file, 0, "", "cannot read the file: " + loaded.detail}});
  }
  return loaded.root;
}

std::vector<std::string> ModelNames(const std::string& folder) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(models::ModelsDir()) / folder, ec)) {
    if (e.path().extension() == ".yaml") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

YAML::Node LoadModel(YamlReader& r, const YAML::Node& at, const std::string& path,
                     const std::string& what, const std::string& value, const std::string& folder,
                     const std::string& relative_to, std::string* file) {
  const bool is_path =
      value.find('/') != std::string::npos || value.ends_with(".yaml") || value.ends_with(".yml");
  const std::string name = (is_path ? fs::path(relative_to).parent_path() / value
                                    : fs::path(models::ModelsDir()) / folder / (value + ".yaml"))
                               .string();
  if (file) *file = name;
  const YamlFile loaded = LoadYamlFile(name);
  switch (loaded.problem) {
    case YamlFile::Problem::kNone:
      return loaded.root;
    case YamlFile::Problem::kMissing:
      // A path names a file relative to the scenario; a bare name one of
      // the shipped models: say both, with the models there are.
      r.Error(at, path,
              "no " + what + " file " + name +
                  (is_path ? " (a path is relative to the scenario's folder; a name without '/' "
                             "or .yaml is one of models/" +
                                 folder + "/: " + config::JoinNames(ModelNames(folder)) + ")"
                           : cosim::ClosestHint(value, ModelNames(folder)) + " (models/" + folder +
                                 "/ has: " + config::JoinNames(ModelNames(folder)) + ")"));
      break;
    case YamlFile::Problem::kFolder:
      r.Error(at, path, "cannot read " + what + " file " + name + ": it is not a file (a folder?)");
      break;
    case YamlFile::Problem::kInvalid:
      r.Error(at, path,
              "cannot read " + what + " file " + name + ": not valid YAML" +
                  (loaded.line > 0 ? " at line " + std::to_string(loaded.line) : "") + ": " +
                  loaded.detail);
      break;
    case YamlFile::Problem::kUnreadable:
      r.Error(at, path, "cannot read " + what + " file " + name + ": " + loaded.detail);
      break;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

}  // namespace linesim::loader
