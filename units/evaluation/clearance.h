#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cosim/unit.h"
#include "models/scene.h"

namespace linesim::evaluation {

/// Ground-truth clearance of the robot's body from the scene: every step,
/// the minimum distance between the body box and every obstacle (boxes with
/// a yaw, vertical cylinders) and every carried object (a car body moved
/// along its belt's direction by the belt's travel, gone once lifted off
/// outside models::CarriedTravelRange, the rule the chassis applies), and
/// the contacts, counted as collisions.
///
/// Objects are indexed as the scene lists them: obstacles 0..n-1, then the
/// carried objects n..n+m-1 (`nearest`). Terrain pieces are left out: a
/// terrain piece is something the robot drives on (a ramp, a raised floor),
/// so its distance from the body would be the robot's ground clearance while
/// it drives on it, not a distance from an obstacle; the chassis does not
/// simulate them yet either.
///
/// The body: a box `body_length` x `body_width` x `body_height` centred on
/// base_link's x and y, its bottom `body_bottom` above base_link's origin
/// along base_link's z, posed by `position_3d` and `orientation`.
///
/// Contact: FCL's collide() of the body with an object reports an
/// intersection (penetration, or touching within FCL's GJK tolerance,
/// 1e-6). A collision is one contact event with one object: the object is
/// in contact at this communication point and was not at the previous one
/// (at the start: not before it). Staying in contact counts nothing; leaving
/// and touching again counts again; two objects touched at once count two.
/// A lifted-off object is not in contact.
///
/// Distances come from FCL 0.7 (libccd GJK) through a
/// fcl::DynamicAABBTreeCollisionManager holding the scene's objects: the
/// obstacles are registered once; a carried object is moved and updated in
/// the tree only when its belt's travel changed. The body is the query
/// object. `query`:
///  - "full": the manager's distance query with a callback that computes
///    each visited pair (pruned by the tree's AABB distance against the
///    current best), and a collide query every step.
///  - "pruned" (default; the same results to GJK's tolerance): the exact
///    distance to the previous step's nearest object first, then the
///    manager's query skipping every object whose AABB lies at least that
///    far or whose distance bound does (its last exact distance less how far
///    any point of the body and the object moved since: the distance is
///    1-Lipschitz in either's motion), and reusing an object's distance when
///    neither it nor the body moved; carried objects' tree boxes are kept
///    kCarriedMarginM larger than the objects, so the tree is updated only
///    when one leaves its box; the collide query only when the clearance is
///    below kContactSkinM (no object can touch otherwise).
/// FCL's libccd GJK allocates its shape wrapper on every narrow-phase call
/// (inside FCL); the unit itself allocates nothing per step.
class ClearanceUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "clearance";
  /// Below this distance the collide query decides the contacts (pruned
  /// query); GJK's distance tolerance (1e-6 m) is far below it.
  static constexpr double kContactSkinM = 1e-3;
  /// Pruned query: margin of the box a carried object's tree node holds
  /// (at 0.1 m/s the tree is updated every 1 s instead of every step).
  static constexpr double kCarriedMarginM = 0.1;

  /// Throws cosim::UnitError if a carried object names no belt of the scene.
  ClearanceUnit(std::string name, const models::Scene& scene);
  ~ClearanceUnit() override;

  /// Validates the parameters (throws cosim::UnitError), builds the body
  /// and evaluates the start (no contact before it).
  void Initialize() override;
  /// The outputs follow the pose and belt travel at each communication
  /// point; the running minimum and the count include it, without
  /// committing it (idempotent).
  void UpdateOutputs() override;
  /// Commits the communication point's clearance and contacts to the
  /// running minimum and the count.
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  /// Count of scene objects considered (obstacles + carried objects).
  int object_count() const { return static_cast<int>(obstacle_count_ + carried_.size()); }
  /// Narrow-phase distance and collide calls of the last evaluation (for
  /// the benchmark and tests of the pruning).
  int last_narrow_phase_calls() const { return narrow_calls_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  struct Fcl;
  struct Carried {
    int belt = 0;
    double x0_m = 0.0, y0_m = 0.0, z_m = 0.0;
    double axis_x = 1.0, axis_y = 0.0;
    double travel_min_m = 0.0, travel_max_m = 0.0;
  };
  friend struct ClearanceCallbacks;

  void BuildBody();
  /// Every distance bound unknown (start, restore).
  void ForgetBounds();
  /// Evaluates the current inputs unless they are those of the last
  /// evaluation; then fills the outputs from the committed state.
  void EvaluateIfChanged();
  void Evaluate();
  void MoveCarried();
  void FillOutputs();

  std::size_t obstacle_count_ = 0;
  std::vector<Carried> carried_;
  std::unique_ptr<Fcl> fcl_;

  // Parameters.
  double body_length_, body_width_, body_height_, body_bottom_;
  double max_clearance_ = 100.0;
  std::string query_ = "pruned";
  bool pruned_ = true;

  // Inputs.
  std::vector<double> position_3d_ = std::vector<double>(3, 0.0);
  std::vector<double> orientation_ = {1.0, 0.0, 0.0, 0.0};
  std::vector<double> belt_travel_;

  // Outputs.
  double clearance_ = 0.0;
  std::int64_t nearest_ = -1;
  double in_contact_ = 0.0;
  double min_clearance_ = 0.0;
  std::int64_t collisions_ = 0;

  // The last evaluation: its inputs (NaN: none yet), result, contacts.
  std::vector<double> evaluated_inputs_;
  double distance_ = 0.0;
  std::int64_t distance_index_ = -1;
  std::vector<std::uint8_t> active_;      // per object: in the scene (not lifted off)
  std::vector<std::uint8_t> contact_now_;  // per object, this evaluation
  std::vector<double> carried_travel_;    // travel each carried object was placed at
  int narrow_calls_ = 0;
  // Pruned query: per object a lower bound of its distance (its last exact
  // distance less how far the body and it moved since), and the body's last
  // pose (in Fcl).
  std::vector<double> lower_bound_;
  std::vector<std::uint8_t> exact_;  // lower_bound_[i] is its distance (nothing moved since)
  double body_radius_ = 0.0;  // half diagonal of the body box
  bool have_previous_pose_ = false;

  // Committed at each step.
  std::vector<std::uint8_t> contact_before_;  // per object, at the last step
  double committed_min_ = 0.0;
  std::int64_t committed_collisions_ = 0;
  std::int64_t previous_nearest_ = -1;  // where the pruned query starts
};

}  // namespace linesim::evaluation
