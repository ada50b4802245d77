#pragma once

#include "loader/assembly/concerns.h"

/// Workers on the line and the S300's safety fields (issue 22): the
/// scenario's `workers:` and `safety:` sections.
namespace linesim::loader::assembly {

inline constexpr const char* kSafety = "safety";
inline constexpr const char* kPersonClearance = "person_clearance";

/// safety: the S300's field sets on one laser's scan (a safety_field unit)
/// between the task and the wheel controller: after AddControl, before
/// AddTask (it takes over the wheel controller's command inputs in `s`).
/// Nothing when the scenario has no `safety:` section.
void AddSafetyFields(SystemBuilder& b, const RobotFile& robot, Signals& s, RobotInfo& info);

/// workers: a worker unit per entry, its legs and torso connected to every
/// laser on the robot (moving cylinders) and to a person_clearance unit
/// (robot-person distance and collisions), with their metrics and
/// recording; and the safety unit's metrics. After AddEvaluation (it adds
/// to its metrics), before AddRecording.
void AddWorkers(SystemBuilder& b, const RobotFile& robot, Signals& s, RobotInfo& info);

}  // namespace linesim::loader::assembly
