#pragma once

#include <string>

/// The JSON Schemas (schema encoding "jsonschema") of the Foxglove message
/// types linesim writes with message encoding "json", written from
/// Foxglove's schema reference (docs.foxglove.dev, "Message schemas": the
/// fields, their types and meanings). Foxglove recognises a channel's type
/// by the schema's name (foxglove.FrameTransforms, foxglove.LaserScan,
/// foxglove.SceneUpdate, foxglove.Log); the schema text tells a reader the fields.
namespace linesim::mcap {

std::string FrameTransformsSchema();
std::string LaserScanSchema();
std::string SceneUpdateSchema();
std::string LogSchema();

}  // namespace linesim::mcap
