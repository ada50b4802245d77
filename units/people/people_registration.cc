// Registers the people family's unit types (see config/unit_registry.h).
#include "config/unit_registry.h"
#include "units/people/person_clearance_unit.h"
#include "units/people/worker_unit.h"

namespace linesim::people {
namespace {

std::unique_ptr<cosim::Unit> MakeWorker(const config::UnitBuildContext& c) {
  const std::size_t issues_before = c.reader.issues().size();
  auto waypoints = config::ReadPoints(c, "waypoints", 1);
  if (c.reader.issues().size() != issues_before || waypoints.empty()) return nullptr;
  const auto robots = c.reader.Integer(c.parameters, c.path, "robots", 0, 0, 10000);
  return std::make_unique<WorkerUnit>(c.name, std::move(waypoints), static_cast<int>(robots));
}

const config::UnitTypeRegistrar kWorker(
    {WorkerUnit::kTypeName,
     "a person walking along waypoints (speed profile, pauses, gait): two legs at a "
     "scanner's height and a torso, as moving cylinders the lasers and the clearance see",
     "",
     {{"waypoints", "list of points [x, y] (m, map): where the worker walks, stopping at each"},
      {"robots",
       "number of robots the worker yields to (adds the input robots, 10 numbers each, and "
       "stop_distance; default 0)"}},
     MakeWorker});

std::unique_ptr<cosim::Unit> MakePersonClearance(const config::UnitBuildContext& c) {
  const std::size_t issues_before = c.reader.issues().size();
  const auto workers = c.reader.Integer(c.parameters, c.path, "workers", 1, 1, 10000);
  std::vector<std::string> names;
  const YAML::Node list = config::Child(c.parameters, "worker_names");
  const std::string path = config::JoinPath(c.path, "worker_names");
  if (list.IsDefined() && !list.IsNull() && c.reader.ExpectSequence(list, path)) {
    if (list.size() != static_cast<std::size_t>(workers)) {
      c.reader.Error(list, path,
                     "expected one name per worker (" + std::to_string(workers) + "), got " +
                         std::to_string(list.size()));
    }
    for (std::size_t k = 0; k < list.size(); ++k) {
      if (auto name = c.reader.AsString(list[k], config::JoinPath(path, std::to_string(k)))) {
        names.push_back(*name);
      }
    }
  }
  if (c.reader.issues().size() != issues_before) return nullptr;
  return std::make_unique<PersonClearanceUnit>(c.name, static_cast<int>(workers), std::move(names));
}

const config::UnitTypeRegistrar kPersonClearance(
    {PersonClearanceUnit::kTypeName,
     "distance of the robot's body from the workers' legs and torsos, and robot-person "
     "contacts counted as collisions (per worker)",
     "",
     {{"workers", "number of workers (the input `cylinders` holds 21 numbers each; default 1)"},
      {"worker_names",
       "the workers' names, one per worker, for the contact warnings (default: "
       "worker 0, worker 1, ...)"}},
     MakePersonClearance});

}  // namespace
}  // namespace linesim::people
