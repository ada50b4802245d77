#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "loader/assembly/concerns.h"

/// Sensing and localization providers: who tells the controllers the
/// surface velocity under each wheel (`sensing.surface_velocity`) and the
/// pose (`localization.source`). Each provider is a file in
/// loader/assembly/providers/ that registers itself with a
/// ProviderRegistrar, as unit families register their types
/// (config/unit_registry.h): adding one touches no other file. AddSensing
/// (sensing.cc) runs the chosen ones; below are the building blocks they
/// share.
namespace linesim::loader::assembly {

/// What a provider needs besides the builder: the robot, its start pose,
/// and where the scenario chose it (for errors).
struct ProviderContext {
  const RobotFile& file;
  const StartPose& start;
  const models::Scene& scene;
  YAML::Node at;     // the section the choice is in
  std::string path;  // its key path
};

/// Adds the provider's units and connections, and sets the roles it
/// provides in Signals.
using Provider = std::function<void(SystemBuilder&, const ProviderContext&, Signals&)>;

/// The choice a provider answers.
enum class ProviderRole {
  kSurfaceVelocity,  // sensing.surface_velocity
  kLocalization,     // localization.source
};

/// The providers of a role by name, sorted (a scenario's error lists them
/// as the allowed values).
const std::map<std::string, Provider>& Providers(ProviderRole role);

/// `const ProviderRegistrar kX(ProviderRole::kLocalization, "name", Fn);` at
/// namespace scope of a provider's file registers it when the program
/// starts; a name registered twice for one role aborts. The providers'
/// library is linked whole (loader/CMakeLists.txt): nothing calls a
/// registrar.
struct ProviderRegistrar {
  ProviderRegistrar(ProviderRole role, std::string name, Provider provider);
};

/// The mounts of one kind the scenario left on.
std::vector<const models::SensorMount*> Mounts(const Signals& s, const std::string& kind);

/// Whether the scenario left sensors of `kind` on; if not, says so at the
/// key that chose `choice` (the scenario turned them off, or the robot
/// carries none).
bool Require(SystemBuilder& b, const ProviderContext& c, const Signals& s, const std::string& kind,
             const std::string& choice);

/// The unit steps at the control period (recorded as derived from it).
void SetStep(SystemBuilder& b, const std::string& unit);

/// initial_x, initial_y, initial_yaw of a unit's parameters `p`.
void SetInitialPose(Parameters& p, const StartPose& start);

/// The numbers of one sensor unit's parameters as the unit will get them:
/// the scenario's or the robot's setting if the expansion has one, else the
/// device's model file (the mount's or the scenario's `model`, read once).
class DeviceNumbers {
 public:
  DeviceNumbers(SystemBuilder& b, const ProviderContext& c, const models::SensorMount& m);
  /// nullopt when neither gives it, or (reported) when it is not a number.
  std::optional<double> Get(const std::string& key) const;
  /// A number the estimator cannot do without (reported when missing).
  double Required(const std::string& key) const;
  /// The device's beam_count as the laser unit takes it (a whole number
  /// from 1 to kMaxBeams), or 0 when it is not one: the laser unit reports
  /// it at its key, and nothing converts an out-of-range number to int.
  int BeamCount() const { return WholeBeams(Required("beam_count")); }
  static int WholeBeams(double n) {
    return n >= 1.0 && n <= kMaxBeams && n == static_cast<double>(static_cast<int>(n))
               ? static_cast<int>(n)
               : 0;
  }
  static constexpr double kMaxBeams = 100000;  // the laser_scanner unit's limit

 private:
  YAML::Node Find(const std::string& key) const;

  SystemBuilder& b_;
  const ProviderContext& c_;
  const models::SensorMount& m_;
  YAML::Node params_, model_;
};

/// The robot's lasers into a scan matcher `unit` (laser_localization or
/// perfect_match_localization): per laser its mount (with mount_z when
/// `with_z`) and beam geometry from its device numbers, and its ranges,
/// scan count and scan time as the unit's inputs _0, _1, ...; `more` reads
/// further numbers of each laser's device (its model file read once).
void WireLasers(SystemBuilder& b, const ProviderContext& c, const Signals& s, const char* unit,
                bool with_z, const std::function<void(const DeviceNumbers&)>& more = {});

/// hector_mapping on the robot's lasers (paper 1 Sec. IV-B): one
/// laser_localization unit matching every laser's scans against the scene.
void AddLaserLocalization(SystemBuilder& b, const ProviderContext& c, Signals& s);

/// The odometry's twist into a matcher (for motion_prediction: odometry).
void ConnectOdometryToMatcher(SystemBuilder& b, const char* matcher = kLaserLocalization);

/// The EKF of odometry and a matcher's poses (delayed to their scan's time).
void AddPoseFusion(SystemBuilder& b, const ProviderContext& c, Signals& s, const char* matcher);

/// Dead reckoning from the wheel encoders (swerve: the module kinematics;
/// differential: skid-steer with the controller's effective track), with
/// paper 1's Eq. 3 rectification by the surface velocity under each wheel.
void AddOdometry(SystemBuilder& b, const ProviderContext& c, Signals& s);

/// The PX4Flow units' messages into a surface unit's sensor inputs (both
/// surface providers read them alike), their mounts and the wheel count
/// into its parameters `p`.
void ConnectFlowSensors(SystemBuilder& b, const std::vector<const models::SensorMount*>& flows,
                        const models::RobotDescription& robot, const std::string& unit,
                        Parameters& p);

}  // namespace linesim::loader::assembly
