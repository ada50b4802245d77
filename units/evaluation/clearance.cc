#include "units/evaluation/clearance.h"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "cosim/variable_table.h"

namespace linesim::evaluation {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

void* IndexTag(std::size_t i) { return reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)); }
std::size_t IndexOf(const fcl::CollisionObjectd* o) {
  return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(o->getUserData()));
}

/// The FCL shape of a scene solid (FCL's box and cylinder are centred on
/// their frame's origin, the cylinder's axis along z), and the height of its
/// centre above the floor.
std::shared_ptr<fcl::CollisionGeometryd> SolidShape(const models::Solid& s, double* center_z) {
  *center_z = s.bottom_m + 0.5 * s.height_m;
  if (s.kind == models::Solid::Kind::kCylinder) {
    return std::make_shared<fcl::Cylinderd>(s.radius_m, s.height_m);
  }
  return std::make_shared<fcl::Boxd>(s.length_m, s.width_m, s.height_m);
}

fcl::Matrix3d Yaw(double yaw_rad) {
  return fcl::Matrix3d(Eigen::AngleAxisd(yaw_rad, fcl::Vector3d::UnitZ()));
}

/// A collision object whose AABB can be set: the tree keeps a carried
/// object's AABB enlarged by a margin, so that it is updated only when the
/// object leaves it (the object's own AABB is put back afterwards).
class Object : public fcl::CollisionObjectd {
 public:
  using fcl::CollisionObjectd::CollisionObjectd;
  void SetAabb(const fcl::AABBd& box) { aabb = box; }
};

}  // namespace

struct ClearanceUnit::Fcl {
  // Obstacles then carried objects, each tagged with its index.
  std::vector<std::unique_ptr<Object>> objects;
  // Per carried object: the AABB its tree node holds (pruned query).
  std::vector<fcl::AABBd> fat;
  fcl::DynamicAABBTreeCollisionManagerd manager;
  std::unique_ptr<fcl::CollisionObjectd> body;
  std::vector<fcl::CollisionObjectd*> moved;  // reserved: no allocation per step
  // The body's pose at the last evaluation (pruned query's bounds).
  fcl::Vector3d previous_centre = fcl::Vector3d::Zero();
  Eigen::Quaterniond previous_q = Eigen::Quaterniond::Identity();

  fcl::DistanceRequestd distance_request;
  fcl::DistanceResultd distance_result;
  fcl::CollisionRequestd collision_request;
  fcl::CollisionResultd collision_result;
};

/// What the manager's callbacks see (o1: the scene object, o2: the body).
struct ClearanceCallbacks {
  ClearanceUnit* unit;
  double best;
  std::int64_t best_index;
  std::int64_t skip;  // already computed (pruned query); -1: none

  double Narrow(fcl::CollisionObjectd* object, fcl::CollisionObjectd* body) {
    ClearanceUnit::Fcl& f = *unit->fcl_;
    ++unit->narrow_calls_;
    f.distance_result.clear();
    return fcl::distance(object, body, f.distance_request, f.distance_result);
  }
  // The distance of object i, reused when neither it nor the body moved
  // since it was computed (pruned query).
  double Exact(std::size_t i, fcl::CollisionObjectd* object, fcl::CollisionObjectd* body) {
    if (unit->exact_[i]) return unit->lower_bound_[i];
    const double d = Narrow(object, body);
    unit->lower_bound_[i] = d;
    unit->exact_[i] = 1;
    return d;
  }
  void Offer(double d, std::size_t i) {
    if (d < best) {
      best = d;
      best_index = static_cast<std::int64_t>(i);
    }
  }

  // "full": every pair the tree's AABB pruning leaves.
  static bool Full(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data,
                   double& dist) {
    auto& q = *static_cast<ClearanceCallbacks*>(data);
    const std::size_t i = IndexOf(o1);
    if (q.unit->active_[i]) q.Offer(q.Narrow(o1, o2), i);
    dist = q.best;
    return q.best <= 0.0;  // touching: nothing can be nearer
  }

  // "pruned": skips an object whose AABB is at least as far as the best
  // (the tree does this for inner nodes; this also covers the first leaf it
  // reaches, before it has a distance, and the seeded best).
  static bool Pruned(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data,
                     double& dist) {
    auto& q = *static_cast<ClearanceCallbacks*>(data);
    const std::size_t i = IndexOf(o1);
    ClearanceUnit& u = *q.unit;
    if (u.active_[i] && static_cast<std::int64_t>(i) != q.skip && u.lower_bound_[i] < q.best &&
        o1->getAABB().distance(o2->getAABB()) < q.best) {
      q.Offer(q.Exact(i, o1, o2), i);
    }
    dist = q.best;
    return q.best <= 0.0;
  }

  // Contacts: marks every active object that intersects the body.
  static bool Contact(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    auto& q = *static_cast<ClearanceCallbacks*>(data);
    const std::size_t i = IndexOf(o1);
    if (!q.unit->active_[i]) return false;
    ClearanceUnit::Fcl& f = *q.unit->fcl_;
    ++q.unit->narrow_calls_;
    f.collision_result.clear();
    if (fcl::collide(o1, o2, f.collision_request, f.collision_result) > 0) {
      q.unit->contact_now_[i] = 1;
    }
    return false;  // all of them
  }
};

ClearanceUnit::ClearanceUnit(std::string name, const models::Scene& scene)
    : cosim::Unit(kTypeName, std::move(name)), fcl_(std::make_unique<Fcl>()) {
  body_length_ = body_width_ = body_height_ = body_bottom_ = kNaN;
  Fcl& f = *fcl_;
  obstacle_count_ = scene.obstacles.size();
  for (const models::Obstacle& o : scene.obstacles) {
    double z = 0.0;
    auto shape = SolidShape(o.solid, &z);
    f.objects.push_back(std::make_unique<Object>(shape, Yaw(o.solid.yaw_rad),
                                                 fcl::Vector3d(o.solid.x_m, o.solid.y_m, z)));
  }
  for (const models::CarriedObject& c : scene.carried) {
    if (c.belt < 0 || static_cast<std::size_t>(c.belt) >= scene.belts.size()) {
      throw cosim::UnitError(Where() + ": carried object '" + c.name + "' is on belt " +
                             std::to_string(c.belt) + ", not one of the scene's " +
                             std::to_string(scene.belts.size()) + " belts");
    }
    const models::Rect& area = scene.belts[static_cast<std::size_t>(c.belt)].area;
    Carried k;
    k.belt = c.belt;
    k.x0_m = c.solid.x_m;
    k.y0_m = c.solid.y_m;
    k.axis_x = std::cos(area.direction_rad);
    k.axis_y = std::sin(area.direction_rad);
    const auto range = models::CarriedTravelRange(area, c.solid);
    k.travel_min_m = range[0];
    k.travel_max_m = range[1];
    auto shape = SolidShape(c.solid, &k.z_m);
    f.objects.push_back(std::make_unique<Object>(shape, Yaw(c.solid.yaw_rad),
                                                 fcl::Vector3d(k.x0_m, k.y0_m, k.z_m)));
    carried_.push_back(k);
  }
  for (std::size_t i = 0; i < f.objects.size(); ++i) {
    f.objects[i]->setUserData(IndexTag(i));
    f.objects[i]->computeAABB();
  }
  // Registered once; setup() balances the tree.
  for (auto& o : f.objects) f.manager.registerObject(o.get());
  f.manager.setup();
  f.moved.reserve(carried_.size());
  for (std::size_t k = 0; k < carried_.size(); ++k) {
    f.fat.push_back(f.objects[obstacle_count_ + k]->getAABB());
  }
  // libccd's GJK (FCL's default) for both queries; one contact is enough
  // to know that an object touches.
  f.distance_request.gjk_solver_type = fcl::GST_LIBCCD;
  f.collision_request.num_max_contacts = 1;

  const std::size_t n = f.objects.size();
  active_.assign(n, 1);
  lower_bound_.assign(n, -kInf);
  exact_.assign(n, 0);
  contact_now_.assign(n, 0);
  contact_before_.assign(n, 0);
  carried_travel_.assign(carried_.size(), kNaN);
  belt_travel_.assign(scene.belts.size(), 0.0);

  auto& v = variables();
  v.Parameter("body_length", "m", &body_length_,
              "robot body box length along base_link x (the robot description's body)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("body_width", "m", &body_width_,
              "robot body box width along base_link y (the robot description's body)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("body_height", "m", &body_height_, "robot body box height",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("body_bottom", "m", &body_bottom_,
              "height of the body box's bottom above base_link's origin, along base_link z "
              "(the box is centred on base_link x, y; the robot description's bottom_m, as "
              "the chassis's body_bottom; negative: below it)",
              cosim::Rule::Finite().NoDefault());
  v.Parameter("max_clearance", "m", &max_clearance_,
              "clearance reported when no object is nearer (none, or all lifted off); also "
              "the farthest the distance query looks",
              cosim::Rule::Positive());
  v.Parameter("query", &query_,
              "pruned: exact distance to the last nearest object first, others only when "
              "their AABB is nearer, contacts only below 1 mm; full: the manager's distance "
              "and collide queries every step (same results, slower)",
              cosim::Rule::OneOf({"pruned", "full"}));

  v.Input("position_3d", "m", &position_3d_, "base_link origin in the map frame (x, y, z)");
  v.Input("orientation", "1", &orientation_, "base_link orientation in map: quaternion w, x, y, z");
  std::vector<std::string> inputs = {"position_3d", "orientation"};
  if (!belt_travel_.empty()) {
    v.Input("belt_travel", "m", &belt_travel_,
            "distance each scene belt's surface has moved since t = 0 (places carried objects)");
    inputs.push_back("belt_travel");
  }
  v.Output("clearance", "m", &clearance_,
           "minimum distance between the body box and the scene's objects now (0 in contact; "
           "max_clearance when none is nearer)",
           inputs);
  v.Output("nearest", &nearest_,
           "index of the nearest object: obstacles 0..n-1, then carried objects n..; -1 when "
           "none is within max_clearance",
           inputs);
  v.Output("in_contact", "1", &in_contact_, "1 when the body touches or penetrates an object",
           inputs);
  v.Output("min_clearance", "m", &min_clearance_,
           "minimum clearance since the start (metric min_clearance_m: its final value)", inputs);
  v.Output("collisions", &collisions_,
           "contact events since the start: an object touched now that was not at the previous "
           "communication point (metric collisions: its final value)",
           inputs);
  evaluated_inputs_.assign(7 + belt_travel_.size(), kNaN);
}

ClearanceUnit::~ClearanceUnit() = default;

void ClearanceUnit::BuildBody() {
  fcl_->body = std::make_unique<fcl::CollisionObjectd>(
      std::make_shared<fcl::Boxd>(body_length_, body_width_, body_height_));
  body_radius_ =
      0.5 * std::sqrt(body_length_ * body_length_ + body_width_ * body_width_ +
                      body_height_ * body_height_);
}

void ClearanceUnit::ForgetBounds() {
  std::fill(lower_bound_.begin(), lower_bound_.end(), -kInf);
  std::fill(exact_.begin(), exact_.end(), 0);
  have_previous_pose_ = false;
}

void ClearanceUnit::Initialize() {
  ThrowIfBadParameters();
  pruned_ = query_ == "pruned";
  BuildBody();
  // The start: nothing touched before it, nothing committed.
  std::fill(contact_before_.begin(), contact_before_.end(), 0);
  committed_min_ = max_clearance_;
  committed_collisions_ = 0;
  previous_nearest_ = -1;
  std::fill(evaluated_inputs_.begin(), evaluated_inputs_.end(), kNaN);
  ForgetBounds();
  EvaluateIfChanged();
}

void ClearanceUnit::UpdateOutputs() { EvaluateIfChanged(); }

void ClearanceUnit::MoveCarried() {
  Fcl& f = *fcl_;
  f.moved.clear();
  for (std::size_t k = 0; k < carried_.size(); ++k) {
    const Carried& c = carried_[k];
    const double s = belt_travel_[static_cast<std::size_t>(c.belt)];
    if (s == carried_travel_[k]) continue;  // did not move
    const std::size_t i = obstacle_count_ + k;
    // Its distance bound drops by the distance it moved along its belt.
    lower_bound_[i] -= std::abs(s - carried_travel_[k]);
    exact_[i] = 0;
    if (!(lower_bound_[i] >= -kInf)) lower_bound_[i] = -kInf;  // first placement: NaN
    carried_travel_[k] = s;
    // Past an end of its belt: lifted off the line, gone from the scene.
    active_[i] = (c.travel_min_m <= s && s <= c.travel_max_m) ? 1 : 0;
    if (!active_[i]) continue;
    Object& o = *f.objects[i];
    o.setTranslation(fcl::Vector3d(c.x0_m + s * c.axis_x, c.y0_m + s * c.axis_y, c.z_m));
    o.computeAABB();
    if (!pruned_) {
      f.moved.push_back(&o);  // "full": the tree follows every move
    } else if (!f.fat[k].contain(o.getAABB())) {
      // Left the box its tree node holds: a new one, kCarriedMarginM
      // larger on every side, so that the next ~margin / speed steps need
      // no update of the tree.
      f.fat[k] = o.getAABB();
      f.fat[k].expand(fcl::Vector3d::Constant(kCarriedMarginM));
      o.SetAabb(f.fat[k]);
      f.moved.push_back(&o);
    }
  }
  if (f.moved.empty()) return;
  f.manager.update(f.moved);
  for (fcl::CollisionObjectd* o : f.moved) o->computeAABB();  // its own box again
}

void ClearanceUnit::Evaluate() {
  Fcl& f = *fcl_;
  narrow_calls_ = 0;
  MoveCarried();

  // The body: centred on base_link x, y; its centre body_bottom + height / 2
  // above base_link's origin along base_link z.
  Eigen::Quaterniond q(orientation_[0], orientation_[1], orientation_[2], orientation_[3]);
  const double norm = q.norm();
  if (norm > 0.0 && std::isfinite(norm)) {
    q.coeffs() /= norm;
  } else {
    q = Eigen::Quaterniond::Identity();  // DoStep refuses it
  }
  const fcl::Matrix3d r = q.toRotationMatrix();
  const fcl::Vector3d p(position_3d_[0], position_3d_[1], position_3d_[2]);
  const fcl::Vector3d centre =
      p + r * fcl::Vector3d(0.0, 0.0, body_bottom_ + 0.5 * body_height_);
  fcl::CollisionObjectd& body = *f.body;
  body.setTransform(r, centre);
  body.computeAABB();

  // How far any point of the body moved since the last evaluation: its
  // centre's displacement plus, for the turn between the two orientations
  // (angle a), 2 sin(a / 2) times the half diagonal; 2 sin(a / 2) is twice
  // the norm of the vector part of q q_prev^-1. Every object's distance
  // bound drops by it (the distance is 1-Lipschitz in each body's motion).
  if (have_previous_pose_ &&
      !(centre == f.previous_centre && q.coeffs() == f.previous_q.coeffs())) {
    const Eigen::Quaterniond turn = q * f.previous_q.conjugate();
    const double moved =
        (centre - f.previous_centre).norm() + 2.0 * turn.vec().norm() * body_radius_;
    for (double& b : lower_bound_) b -= moved;
    std::fill(exact_.begin(), exact_.end(), 0);
  }
  f.previous_centre = centre;
  f.previous_q = q;
  have_previous_pose_ = true;

  ClearanceCallbacks query{this, max_clearance_, -1, -1};
  const auto n = static_cast<std::int64_t>(f.objects.size());
  if (pruned_) {
    // The last nearest object is most likely still the nearest: its exact
    // distance bounds the search from the start.
    const std::int64_t seed = previous_nearest_;
    if (seed >= 0 && seed < n && active_[static_cast<std::size_t>(seed)]) {
      const auto i = static_cast<std::size_t>(seed);
      query.Offer(query.Exact(i, f.objects[i].get(), &body), i);
      query.skip = seed;
    }
    f.manager.distance(&body, &query, &ClearanceCallbacks::Pruned);
  } else {
    f.manager.distance(&body, &query, &ClearanceCallbacks::Full);
  }
  distance_ = query.best;
  distance_index_ = query.best_index;

  std::fill(contact_now_.begin(), contact_now_.end(), 0);
  // An intersecting object has a distance <= 0 (it would be the best);
  // above the skin none can touch.
  if (!pruned_ || distance_ < kContactSkinM) {
    f.manager.collide(&body, &query, &ClearanceCallbacks::Contact);
  }
}

void ClearanceUnit::EvaluateIfChanged() {
  // Re-evaluate only for new inputs: the master calls UpdateOutputs and then
  // DoStep with the same ones.
  std::size_t j = 0;
  bool same = true;
  const auto check = [&](double x) {
    if (!(evaluated_inputs_[j] == x)) {
      evaluated_inputs_[j] = x;
      same = false;
    }
    ++j;
  };
  for (double x : position_3d_) check(x);
  for (double x : orientation_) check(x);
  for (double x : belt_travel_) check(x);
  if (!same) Evaluate();
  FillOutputs();
}

void ClearanceUnit::FillOutputs() {
  std::int64_t first_contact = -1;
  std::int64_t new_contacts = 0;
  for (std::size_t i = 0; i < contact_now_.size(); ++i) {
    if (!contact_now_[i]) continue;
    if (first_contact < 0) first_contact = static_cast<std::int64_t>(i);
    if (!contact_before_[i]) ++new_contacts;
  }
  const bool touching = first_contact >= 0;
  in_contact_ = touching ? 1.0 : 0.0;
  clearance_ = touching ? 0.0 : std::clamp(distance_, 0.0, max_clearance_);
  nearest_ = distance_index_;
  if (touching &&
      (distance_index_ < 0 || !contact_now_[static_cast<std::size_t>(distance_index_)])) {
    nearest_ = first_contact;
  }
  min_clearance_ = std::min(committed_min_, clearance_);
  collisions_ = committed_collisions_ + new_contacts;
}

cosim::StepResult ClearanceUnit::DoStep(cosim::TimeNs t, cosim::TimeNs) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  double norm2 = 0.0;
  for (double x : orientation_) norm2 += x * x;
  if (!(norm2 > 1e-12)) return Fail("input 'orientation' is not a rotation (zero quaternion)");
  EvaluateIfChanged();
  committed_min_ = min_clearance_;
  committed_collisions_ = collisions_;
  contact_before_ = contact_now_;  // same size: no allocation
  previous_nearest_ = nearest_;
  return cosim::StepResult::kOk;
}

void ClearanceUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals = {committed_min_};
  state.integers = {committed_collisions_, previous_nearest_};
  for (std::uint8_t c : contact_before_) state.integers.push_back(c);
}

void ClearanceUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t n = contact_before_.size();
  if (state.reals.size() != 1 || state.integers.size() != 2 + n) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected 1 and " + std::to_string(2 + n));
  }
  committed_min_ = state.reals[0];
  committed_collisions_ = state.integers[0];
  previous_nearest_ = state.integers[1];
  for (std::size_t i = 0; i < n; ++i) contact_before_[i] = state.integers[2 + i] != 0 ? 1 : 0;
  pruned_ = query_ == "pruned";
  if (!fcl_->body) BuildBody();
  // Evaluate the restored inputs afresh (carried objects placed again).
  std::fill(evaluated_inputs_.begin(), evaluated_inputs_.end(), kNaN);
  std::fill(carried_travel_.begin(), carried_travel_.end(), kNaN);
  ForgetBounds();
}

}  // namespace linesim::evaluation
