#include "mcap/foxglove_schemas.h"

#include <nlohmann/json.hpp>

namespace linesim::mcap {

namespace {

using Json = nlohmann::ordered_json;

// The descriptions are linesim's own words for what each field holds.
Json Object(const char* title, const char* description, Json properties) {
  Json o;
  if (title) o["title"] = title;
  if (description) o["description"] = description;
  o["type"] = "object";
  o["properties"] = std::move(properties);
  return o;
}

Json Float(const char* description) { return {{"type", "number"}, {"description", description}}; }
Json Boolean(const char* description) {
  return {{"type", "boolean"}, {"description", description}};
}
Json Text(const char* description) { return {{"type", "string"}, {"description", description}}; }
Json ArrayOf(Json items, const char* description) {
  return {{"type", "array"}, {"items", std::move(items)}, {"description", description}};
}

// Foxglove's time and duration in JSON: whole seconds and nanoseconds.
Json Time(const char* description) {
  return Object(nullptr, description,
                {{"sec", {{"type", "integer"}, {"minimum", 0}}},
                 {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}});
}
Json Duration(const char* description) {
  return Object(nullptr, description,
                {{"sec", {{"type", "integer"}}},
                 {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}});
}

Json Xyz(const char* title, const char* description) {
  return Object(title, description,
                {{"x", Float("along x")}, {"y", Float("along y")}, {"z", Float("along z")}});
}
Json Quaternion(const char* description) {
  return Object("foxglove.Quaternion", description,
                {{"x", Float("x")}, {"y", Float("y")}, {"z", Float("z")}, {"w", Float("w")}});
}
Json Pose(const char* description) {
  return Object("foxglove.Pose", description,
                {{"position", Xyz("foxglove.Point3", "position (m)")},
                 {"orientation", Quaternion("orientation")}});
}
Json Color(const char* description) {
  return Object("foxglove.Color", description,
                {{"r", Float("red, 0..1")},
                 {"g", Float("green, 0..1")},
                 {"b", Float("blue, 0..1")},
                 {"a", Float("opacity, 0..1")}});
}
Json Enum(const char* title, const char* description,
          std::initializer_list<std::pair<const char*, int>> values) {
  Json one_of = Json::array();
  for (const auto& [name, value] : values) one_of.push_back({{"title", name}, {"const", value}});
  return {{"title", title}, {"description", description}, {"oneOf", one_of}};
}

}  // namespace

std::string FrameTransformsSchema() {
  const Json transform = Object(
      "foxglove.FrameTransform", "where a child frame is in its parent frame at a time",
      {{"timestamp", Time("time of the transform")},
       {"parent_frame_id", Text("parent frame")},
       {"child_frame_id", Text("child frame")},
       {"translation", Xyz("foxglove.Vector3", "the child frame's origin in the parent frame (m)")},
       {"rotation", Quaternion("the child frame's orientation in the parent frame")}});
  return Object("foxglove.FrameTransforms", "transforms between frames",
                {{"transforms", ArrayOf(transform, "the transforms")}})
      .dump();
}

std::string LaserScanSchema() {
  return Object("foxglove.LaserScan", "one scan of a planar laser scanner",
                {{"timestamp", Time("time of the scan")},
                 {"frame_id", Text("frame the scan is in")},
                 {"pose", Pose("origin of the scan in that frame; beams lie in its x-y plane, "
                               "bearings counter-clockwise about its z from its +x")},
                 {"start_angle", Float("bearing of the first beam (rad)")},
                 {"end_angle", Float("bearing of the last beam (rad)")},
                 {"ranges", ArrayOf({{"type", "number"}},
                                    "range of each beam (m), the beams evenly spaced from "
                                    "start_angle to end_angle")},
                 {"intensities", ArrayOf({{"type", "number"}}, "intensity of each beam")}})
      .dump();
}

std::string SceneUpdateSchema() {
  const Json cube = Object("foxglove.CubePrimitive", "a box",
                           {{"pose", Pose("centre and orientation")},
                            {"size", Xyz("foxglove.Vector3", "edge lengths along its axes (m)")},
                            {"color", Color("colour")}});
  const Json sphere =
      Object("foxglove.SpherePrimitive", "a sphere or ellipsoid",
             {{"pose", Pose("centre and orientation")},
              {"size", Xyz("foxglove.Vector3", "diameters along its axes (m)")},
              {"color", Color("colour")}});
  const Json cylinder = Object(
      "foxglove.CylinderPrimitive", "a cylinder or truncated cone along its z axis",
      {{"pose", Pose("centre and orientation")},
       {"size", Xyz("foxglove.Vector3", "extent of its bounding box (m)")},
       {"bottom_scale", Float("bottom face's diameter over the box's, 0..1")},
       {"top_scale", Float("top face's diameter over the box's, 0..1")},
       {"color", Color("colour")}});
  const Json line = Object(
      "foxglove.LinePrimitive", "points joined by lines",
      {{"type", Enum("foxglove.LineType", "how the points are joined",
                     {{"LINE_STRIP", 0}, {"LINE_LOOP", 1}, {"LINE_LIST", 2}})},
       {"pose", Pose("origin of the points")},
       {"thickness", Float("line width")},
       {"scale_invariant", Boolean("true: thickness in screen pixels; false: in metres")},
       {"points", ArrayOf(Xyz("foxglove.Point3", nullptr), "the points")},
       {"color", Color("one colour for the whole line")},
       {"colors", ArrayOf(Color(nullptr), "a colour per point (empty: color)")},
       {"indices", ArrayOf({{"type", "integer"}, {"minimum", 0}},
                           "order of the points to join (empty: as listed)")}});
  const Json text = Object("foxglove.TextPrimitive", "a text label",
                           {{"pose", Pose("centre and orientation")},
                            {"billboard", Boolean("true: always faces the viewer")},
                            {"font_size", Float("height of a line of text")},
                            {"scale_invariant", Boolean("true: font_size in screen pixels")},
                            {"color", Color("colour")},
                            {"text", Text("the text")}});
  // Primitives linesim does not write: named by their types only.
  const auto unused = [](const char* title) {
    return ArrayOf({{"title", title}, {"type", "object"}}, "not written by linesim");
  };
  const Json entity = Object(
      "foxglove.SceneEntity", "a thing in the scene, drawn as primitives in one frame",
      {{"timestamp", Time("time of the entity")},
       {"frame_id", Text("frame of its primitives")},
       {"id", Text("identifier: an entity replaces the earlier one of its id on the topic")},
       {"lifetime", Duration("shown this long after its timestamp; zero: until replaced")},
       {"frame_locked", Boolean("true: moves with its frame; false: stays where it was drawn")},
       {"metadata", ArrayOf(Object("foxglove.KeyValuePair", "a key and its value",
                                   {{"key", Text("key")}, {"value", Text("value")}}),
                            "key-value pairs about it")},
       {"arrows", unused("foxglove.ArrowPrimitive")},
       {"cubes", ArrayOf(cube, "boxes")},
       {"spheres", ArrayOf(sphere, "spheres")},
       {"cylinders", ArrayOf(cylinder, "cylinders")},
       {"lines", ArrayOf(line, "lines")},
       {"triangles", unused("foxglove.TriangleListPrimitive")},
       {"texts", ArrayOf(text, "text labels")},
       {"models", unused("foxglove.ModelPrimitive")}});
  const Json deletion =
      Object("foxglove.SceneEntityDeletion", "removes entities",
             {{"timestamp", Time("entities older than this are removed")},
              {"type", Enum("foxglove.SceneEntityDeletionType", "which entities",
                            {{"MATCHING_ID", 0}, {"ALL", 1}})},
              {"id", Text("the entity's id (MATCHING_ID)")}});
  return Object("foxglove.SceneUpdate", "entities to remove, then entities to add or replace",
                {{"deletions", ArrayOf(deletion, "entities to remove")},
                 {"entities", ArrayOf(entity, "entities to add or replace")}})
      .dump();
}

std::string LogSchema() {
  return Object("foxglove.Log", "a log message",
                {{"timestamp", Time("time of the message")},
                 {"level", Enum("foxglove.LogLevel", "how severe",
                                {{"UNKNOWN", 0},
                                 {"DEBUG", 1},
                                 {"INFO", 2},
                                 {"WARNING", 3},
                                 {"ERROR", 4},
                                 {"FATAL", 5}})},
                 {"message", Text("the message")},
                 {"name", Text("what wrote it")},
                 {"file", Text("source file (empty: none)")},
                 {"line", {{"type", "integer"}, {"minimum", 0}, {"description", "line in file"}}}})
      .dump();
}

}  // namespace linesim::mcap
