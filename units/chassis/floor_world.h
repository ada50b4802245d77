#pragma once

// The ODE world of a factory floor with conveyor-belt patches. This header
// exposes ODE types on purpose: it is used by the chassis unit's .cc and by
// tests, never by the loader (units/chassis/chassis_unit.h keeps ODE out).

#include <ode/ode.h>

#include <array>
#include <span>
#include <stdexcept>
#include <vector>

#include "models/scene.h"
#include "models/surface_profile.h"

namespace linesim::chassis {

/// Standard gravity, m/s^2, pointing along -z in every ODE world made here.
inline constexpr double kGravityMps2 = 9.80665;

/// An ODE error or failed internal check (ODE would abort the process).
class OdeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Initialises ODE once per process and allocates ODE's data for the calling
/// thread. Call it in every thread before that thread touches ODE (units may
/// be stepped from TBB workers); after the first call per thread it is a
/// thread-local flag test. The first call also installs process-wide ODE
/// error and debug handlers that throw OdeError instead of aborting; the
/// world that threw must then be rebuilt.
void EnsureOdeForThisThread();

struct SoftParams {
  double erp;
  double cfm;
};
/// ODE's ERP and CFM that make a constraint a spring of stiffness k (N/m or
/// N.m/rad) with damping d, for one implicit step of h_s seconds (ODE
/// manual, "How To Use ERP and CFM"): ERP = h k / (h k + d),
/// CFM = 1 / (h k + d). Used for the contacts and the suspension.
inline SoftParams ErpCfm(double h_s, double k, double d) {
  const double hk = h_s * k;
  return {hk / (hk + d), 1.0 / (hk + d)};
}

/// A rectangular belt patch in the map frame.
struct BeltPatch {
  double center_x_m = 0.0;
  double center_y_m = 0.0;
  double length_m = 1.0;       // along the belt direction
  double width_m = 1.0;        // across it
  double direction_rad = 0.0;  // of the length axis, counter-clockwise from map x
  double mu = 0.8;             // Coulomb coefficient of a wheel on its surface
  // Width of the open gap between the belt's edges and the floor around it
  // (outside `length` x `width`): a contact patch over it carries nothing.
  double edge_gap_m = 0.0;
};

/// The belt travel over which a carried object (its footprint at zero
/// travel: `solid`) lies along belt `b`'s length: its footprint's extent
/// along the belt axis within the belt's two ends. {min, max}; min > 0 or
/// max < 0 when it does not lie on the belt at zero travel.
std::array<double, 2> CarriedTravelRange(const BeltPatch& b, const models::Solid& solid);

/// Normal contact parameters shared by every contact with the floor and the
/// belts (each belt has its own mu: BeltPatch::mu), and the floor's mu.
struct ContactSurface {
  double mu = 0.8;                 // Coulomb coefficient on the floor (dContactApprox1)
  double stiffness_n_per_m = 1e6;  // per contact point
  double damping_n_s_per_m = 1e4;  // per contact point
};

/// The tread of one registered geom: a transient (relaxation-length) brush
/// tyre. Index 0 is along the rolling direction (longitudinal), 1 across it
/// (lateral). The tread's tangential deflection delta obeys
///   d(delta)/dt = v_slip - (|V_x| / sigma) delta,  F = -k delta - d v_slip,
/// |F| <= mu N (see FloorWorld), with k = C / sigma (C the slip stiffness).
struct Tread {
  double stiffness_n_per_m[2] = {0.0, 0.0};  // k = C / sigma
  double damping_n_s_per_m[2] = {0.0, 0.0};  // d
  double relaxation_m[2] = {1.0, 1.0};       // sigma; a geom without axle never relaxes
  // The contact patch (along the rolling direction, across it); 0: a point.
  double patch_length_m = 0.0;
  double patch_width_m = 0.0;
  // The wheel's axle in its body's frame: the rolling direction is axle x
  // normal. All zero: a block (no rolling direction, no relaxation; rows
  // along map x and y projected on the contact plane).
  double axle[3] = {0.0, 0.0, 0.0};
  // Coulomb coefficient of this tread on each surface index (as
  // GeomContact: floor, belts, terrain pieces); empty: the surfaces' own.
  std::vector<double> mu;
};

/// The saved state of one tread (FloorWorld::TreadStates): its deflection
/// and the direction of its saturated force (zero when it was not
/// saturated), both in map.
inline constexpr std::size_t kTreadStateReals = 6;

/// What one geom touched in the last collision pass (the end of the last
/// Step, or Probe).
struct GeomContact {
  // -1 none, 0 floor, k + 1 belt k, belt_count() + 1 + j terrain piece j
  // (FloorWorld::SurfaceAt's numbering): of the deepest contact point (the
  // first of equally deep ones).
  int surface = -1;
  int points = 0;    // contact points found
  double x_m = 0.0;  // mean contact point in map, or the geom position without contact
  double y_m = 0.0;
  double depth_m = 0.0;  // penetration of the deepest contact point (0 without contact)
  // Share of the deepest point's contact patch over each kind of ground:
  // the surface it touches (floor or terrain piece), the belts, the gaps.
  double support_share = 0.0;  // 1 - gap share (0 without contact)
};

/// Owns the dWorld (gravity -z), a joint group for contacts and the static
/// floor plane z = 0 with belt patches on it. Registered geoms (attached to
/// bodies of this world) collide with the floor and the terrain pieces near
/// them once per step, at its end: the points serve contact(i) and the next
/// step's contact joints. Every floor contact point takes the surface
/// velocity of the first belt patch that contains it, else of the floor
/// (zero), through ODE's contact surface motion; a terrain contact point is
/// still.
///
/// Sign of the surface motion: a contact joint enforces
///   fdir_i . (v_body1 - v_body2) = motion_i   (i = 1, 2; fdir2 = n x fdir1)
/// at the contact point. The moving geom's body is always attached as body1
/// and the static floor as body2 (0), so with motion_i = fdir_i . v_surface
/// a sticking contact point moves with the surface.
///
/// Tyres (Tread): every registered geom (a wheel) meets the ground through a
/// transient brush tyre, the first-order (relaxation-length) approximation
/// of the brush model (Pacejka, Tire and Vehicle Dynamics, ch. 3 and 7). Its
/// tangential deflection delta (a 3-vector in map, in the contact plane: the
/// bristle tips stay on the ground when the wheel steers) obeys, per row i
/// (0 along the rolling direction e0 = axle x normal, 1 across it, e1 =
/// normal x e0),
///   d(delta_i)/dt = v_slip,i - (|V_x| / sigma_i) delta_i,
///   F_i = -k_i delta_i - d_i v_slip,i,   |F| <= mu N,
/// v_slip the contact point's velocity over the surface, V_x the wheel
/// centre's along e0. Rolling at steady slip gives F = C slip (creep, C =
/// k sigma); at standstill it is a spring (a parked robot holds). It is
/// implicit inside ODE's LCP: a friction row satisfies
///   fdir_i . v_body1 = motion_i - slip_i F_i
/// (dContactSlip1/2 are the row's CFM, motion1/2 its right-hand side;
/// contact.cpp and step.cpp of ODE 0.16), so with the relaxation taken
/// implicitly (k' = k / (1 + h |V_x| / sigma)) motion_i = e_i . v_surface -
/// (erp / h) delta_i, slip_i = 1 / (h k' + d), erp = h k' / (h k' + d) make
/// F_i = -k delta_i(t + h) - d v_slip,i(t + h): stable at any stiffness and
/// step. The Coulomb bound stays ODE's (dContactApprox1: mu N per row from
/// the same LCP's normal force). After dWorldStep each tread's deflection
/// is advanced with the new slip (the step's force read back through
/// dJointFeedback); when the trial force -k delta - d v_slip exceeds mu N
/// the tread saturates: its force is mu N along -v_slip while it slides
/// (along the trial force while it barely moves), and delta is clipped to
/// that force (elasto-plastic). The friction circle: the rows' bounds are
/// mu N each (a square, the pyramid) while the tread is inside the circle
/// (its forces are the springs', within mu N); once saturated, the next
/// step splits mu between the rows by that direction (dContactMu2: mu |e_i
/// . u|), so a sliding tread's force is mu N along its slip. What remains of
/// the pyramid: the one step in which a tread leaves the circle may reach up
/// to sqrt(2) mu N diagonally, and a saturated tread follows a turn of its
/// force direction one step late. No spin (bore) torque: the patch acts at
/// one point.
///
/// Patches: each contact point stands for a patch of Tread::patch_length
/// x patch_width about it, along e0 and e1. On the floor plane the patch's
/// area is split over the floor, the belts under it and their edge gaps
/// (exact polygon areas, so a patch crossing a belt edge changes
/// continuously); the point takes the area-weighted surface velocity and mu
/// of its supported part, and its rows the supported share of k and d. One
/// point per wheel keeps the dense LCP small; for the linear brush the
/// patch's force is linear in its bristles' slip, so the average is exact
/// for a surface velocity varying across the patch (along it a steady brush
/// weights the leading part more: idealised as uniform). A terrain piece is
/// one surface (no belts on it).
///
/// Sign of the surface motion: a contact joint enforces
///   fdir_i . (v_body1 - v_body2) = motion_i   (i = 1, 2; fdir2 = n x fdir1)
/// at the contact point (without slip). The moving geom's body is always
/// attached as body1 and the static floor as body2 (0), so with motion_i =
/// fdir_i . v_surface a sticking contact point moves with the surface.
///
/// Terrain: rigid tilted boxes (models::TerrainPiece: ramps, a van's load
/// floor, a bump) that the registered geoms (the wheels) stand on exactly as
/// on the floor plane: the same contact rows (soft normal, Coulomb friction
/// with the slip-aligned row while sliding), the friction of the piece's own
/// surface, no surface motion (a piece does not move). A wheel may touch the
/// floor and a piece at once (at a ramp's foot), or two pieces (at its top);
/// each touch is a contact point. The body geoms collide with them as with
/// the obstacles (a belly scraping a crest). Wheels are spheres: ODE's
/// sphere-box test returns one point, the box point nearest the sphere's
/// centre, with the normal from it to the centre, so a wheel rolling over a
/// box edge turns its normal continuously about the edge (no cylinder-box,
/// whose edge contacts ODE approximates).
///
/// Uneven surfaces: the floor (outside the belts) and a terrain piece's top
/// face may carry a height profile h(u, v) (models::SurfaceProfile, zero
/// mean, |h| <= H = its bound) in their own plane's axes (the floor: map x,
/// y; a piece: along, across). The collision geometry stands H above the
/// nominal surface (the floor plane at z = H, a piece's box H thicker
/// upwards), so a wheel touching the true surface anywhere is found; each
/// point found is then moved onto the true surface: along the surface's
/// normal n_s, its depth less (H - h) (n . n_s) and its normal tilted by the
/// gradient, n + (n . n_s) R (-dh/du, -dh/dv, 0) normalised (R the plane's
/// axes), so a face contact meets the tilted tangent plane and an edge or
/// side contact (n . n_s near 0) stays as it was; a point left with no
/// depth is dropped. A belt's contact points are level at z = 0 (depth
/// less H). The depth is the vertical gap to the tangent plane at the
/// point below the contact (exact to the slope's square).
///
/// Objects: static obstacles and belt-carried objects are collision
/// geometry for the registered body geoms (the robot's body box and a
/// payload's box; wheels touch the floor and the terrain only), collided
/// with them at the start of every step. Objects far from the robot cost
/// next to nothing: the obstacles and terrain pieces near the robot (AABBs
/// within kNearMarginM of the AABB of all its geoms) are listed once and
/// listed again only when the robot's AABB leaves that margin, so a step
/// tests one AABB against one box and the near objects only (with no
/// obstacle and no terrain piece in the scene, not even that); a carried object is tested
/// by its AABB translated along its belt, and its geom is moved and
/// collided only when that overlaps the body's. A carried object has no
/// body: it is placed from its belt's travelled distance and its contacts
/// move with it through the contact's surface motion (normal motionN and
/// tangential motion1/2 = the object's velocity), as the belt contacts do.
///
/// A carried object leaves with the belt's end, as a car body is lifted off
/// the line at its end: it rides while its footprint lies along the belt's
/// length (CarriedTravelRange) and, once its leading face passes an end of
/// the belt (travelled beyond that range), it is gone from the scene: it
/// collides with nothing, whatever the belt travels afterwards. (A belt
/// running backwards takes it off at its start the same way.)
class FloorWorld {
 public:
  FloorWorld();
  ~FloorWorld();
  FloorWorld(const FloorWorld&) = delete;
  FloorWorld& operator=(const FloorWorld&) = delete;

  dWorldID world() const { return world_; }

  /// Replaces the belt patches; their velocities start at zero.
  void SetBelts(std::vector<BeltPatch> belts);
  int belt_count() const { return static_cast<int>(belts_.size()); }
  /// Surface velocity of belt k in map, m/s.
  void SetBeltVelocity(int k, double vx_mps, double vy_mps);
  void SetSurface(const ContactSurface& surface) { surface_ = surface; }
  const ContactSurface& surface() const { return surface_; }

  /// Registers a geom attached to a body of this world, with its tread;
  /// returns its index. The caller keeps ownership and must remove it
  /// (ClearGeoms) before destroying it.
  int AddGeom(dGeomID geom, Tread tread);
  void ClearGeoms();
  /// Every tread's state (kTreadStateReals each, in geom order), for a
  /// saved state; SetTreadStates takes them back (throws
  /// std::invalid_argument for a wrong count). ResetTreads unloads them.
  std::vector<double> TreadStates() const;
  void SetTreadStates(std::span<const double> values);
  void ResetTreads();
  /// Elastic energy stored in the treads, sum of k_i delta_i^2 / 2 (J).
  double TreadEnergy() const;
  /// The surface velocity under geom i's contact patch (its deepest point;
  /// zero without contact), area-weighted over the supported part.
  void PatchVelocity(int i, double* vx_mps, double* vy_mps) const;

  /// The geom (attached to a body of this world) that collides with
  /// obstacles, carried objects and terrain pieces, or nullptr (none); the
  /// caller keeps ownership. Replaces every body geom.
  void SetBodyGeom(dGeomID geom, double mu) {
    body_geoms_.clear();
    if (geom != nullptr) body_geoms_.push_back(geom);
    body_mu_ = mu;
    collided_ = false;
  }
  /// One more body geom (a payload's box on the same body), with the same
  /// friction as SetBodyGeom's.
  void AddBodyGeom(dGeomID geom) {
    body_geoms_.push_back(geom);
    collided_ = false;
  }
  /// Adds a static obstacle (box or vertical cylinder standing on the
  /// floor); FloorWorld owns its geom.
  void AddObstacle(const models::Solid& solid);
  int obstacle_count() const { return static_cast<int>(obstacles_.size()); }
  /// Adds a terrain piece (a box placed and tilted as models::TerrainPiece
  /// says: R = Rz(yaw) Ry(-pitch) Rx(roll), + pitch raising its far end)
  /// whose surface has Coulomb coefficient `mu` against the wheels;
  /// FloorWorld owns its geom. Surface index belt_count() + 1 + j for the
  /// j-th piece added (add belts first). Throws std::invalid_argument for a
  /// size that is not positive.
  void AddTerrain(const models::TerrainPiece& piece, double mu,
                  const models::SurfaceProfile& profile = {});
  /// The floor's height profile (the floor plane outside the belts; belts
  /// stay level). See the class comment's "Uneven surfaces".
  void SetFloorProfile(const models::SurfaceProfile& profile);
  int terrain_count() const { return static_cast<int>(terrain_.size()); }
  /// Height of the highest terrain top face above map point (x, y) (its
  /// edges included), or -infinity when no piece's top face is above it.
  double TerrainTopAt(double x_m, double y_m) const;
  /// Adds an object carried by belt `belt` (0-based, < belt_count()), at
  /// `solid` when the belt has travelled 0 m; it leaves the scene when its
  /// footprint passes an end of the belt (see the class comment). Throws
  /// std::out_of_range for a bad belt, std::invalid_argument when its
  /// footprint does not lie along the belt's length at zero travel.
  void AddCarried(const models::Solid& solid, int belt);
  /// Distance belt k's surface has moved since time zero: carried objects
  /// are placed at it (and move on at the belt velocity along the belt
  /// direction within the step).
  void SetBeltTravel(int k, double travel_m);
  /// Other things that move in the scene and that the body meets: other
  /// robots' bodies (models::MovingBox values) and workers' legs and
  /// torsos (models::MovingCylinder values), at the step's start; each moves
  /// on at its velocity within the step. Like a carried object, each is a
  /// geom without a body (it is not pushed: it moves as its own simulation
  /// says), collided with the body geoms when the AABBs overlap, its
  /// contacts moving with it. The count follows the spans' sizes; a box of
  /// length 0 is absent.
  /// Box `own_box` (the robot's own body; -1: none) is left out.
  void SetMovingSolids(std::span<const double> boxes, std::span<const double> cylinders,
                       int own_box = -1);

  /// Surface of the floor plane at map point (x, y): 0 floor, k + 1 for the
  /// first belt k that contains it (edges included). (A contact on terrain
  /// piece j has surface belt_count() + 1 + j.)
  int SurfaceAt(double x_m, double y_m) const;
  /// Velocity in map of a surface index as in GeomContact (zero for the
  /// floor, the terrain and for -1).
  void SurfaceVelocity(int surface, double* vx_mps, double* vy_mps) const;

  /// Collides every registered geom with the floor at the current
  /// positions without making joints, so that contact(i) and the next Step
  /// use them. Call it after moving bodies by hand (positions, rotations);
  /// registering geoms or changing belts makes the next Step collide first.
  void Probe();
  /// One internal step of h_s seconds: contact joints from the last
  /// collision pass, dWorldStep, empty the contact group, collide at the new
  /// positions. Returns false if dWorldStep failed (out of memory); throws
  /// OdeError if ODE reports an error.
  bool Step(double h_s);

  const GeomContact& contact(int i) const { return contacts_[static_cast<std::size_t>(i)]; }

 private:
  // A box on a plane gives at most 4 points; room for odd shapes.
  static constexpr int kMaxPoints = 8;
  // Slip speed above which a saturated tread slides (its force along -slip):
  // far below any sliding speed of interest, far above ODE's residual
  // velocity of a sticking contact (about 1e-12 m/s).
  static constexpr double kSlipAlignMps = 1e-4;
  // Least share of mu a saturated tread's row keeps (see MakeJoints: ODE's
  // LCP fails near 0).
  static constexpr double kMinMuShare = 0.2;

  // Belts a patch can lie on at once; a third one under the same patch is
  // left out (belts are met one edge at a time).
  static constexpr int kPatchBelts = 2;
  // What lies under one contact point's patch: area shares of the surface
  // the point touches (the floor, or its terrain piece), of up to
  // kPatchBelts belts, the rest being gap.
  struct Patch {
    double own_share = 1.0;
    std::array<int, kPatchBelts> belt{-1, -1};
    std::array<double, kPatchBelts> belt_share{0.0, 0.0};
    double Support() const { return own_share + belt_share[0] + belt_share[1]; }
  };
  // The contact points of one geom from its last Collide, the surface (as
  // SurfaceAt) under each and its patch; the feedback of the joints the
  // last Step made from them, and the rows they used.
  struct Points {
    std::array<dContact, kMaxPoints> contact{};
    std::array<int, kMaxPoints> surface{};
    std::array<Patch, kMaxPoints> patch{};
    std::array<dJointFeedback, kMaxPoints> feedback{};
    int count = 0;
    int joints = 0;
  };
  // A tread's state and what the last MakeJoints computed for its update.
  struct TreadState {
    double deflection[3] = {0.0, 0.0, 0.0};
    double force_dir[3] = {0.0, 0.0, 0.0};
    // Rows, relaxation factors 1 / (1 + h |V_x| / sigma_i), patch friction,
    // supported share and surface velocity of the deepest point, for the
    // update after the step.
    double e[2][3] = {};
    double relax[2] = {1.0, 1.0};
    double mu = 0.0, support = 0.0;
    double surface_v[3] = {0.0, 0.0, 0.0};
  };

  /// Collides geom i with the floor and the near terrain into points_[i]
  /// and records contact(i).
  void Collide(std::size_t i);
  /// Lists again the obstacles and terrain pieces near the robot when the
  /// AABB of all its geoms left the listed region.
  void UpdateNear();
  /// Coulomb coefficient of geom i's tread on surface index s (as
  /// GeomContact).
  double SurfaceMu(std::size_t i, int s) const;
  /// The patch of geom i's contact point j (on surface `surface`).
  Patch PatchAt(std::size_t i, const dContactGeom& g, int surface) const;
  /// Rolling direction e0 and e1 = n x e0 of geom i at a contact normal.
  void Rows(std::size_t i, const dReal* normal, double e0[3], double e1[3]) const;
  /// Surface velocity (map) and friction over a patch on surface s.
  void PatchSurface(std::size_t i, const Patch& patch, int s, double v[3], double* mu) const;
  /// Contact joints for the points of geom i (the tyre rows of its tread).
  void MakeJoints(std::size_t i, double h_s, double erp, double cfm);
  /// After dWorldStep: advances geom i's tread deflection (saturation, clip).
  void UpdateTread(std::size_t i, double h_s);
  /// Contact joints between the body geom and the objects it touches.
  void CollideObjects(double erp, double cfm);
  /// Contact joints for the points where body geom `body_geom` touches
  /// `object` (moving at velocity v in map).
  void CollideObject(dGeomID body_geom, dGeomID object, const double v[3]);
  /// Speed of carried object i along its belt's direction.
  double CarriedSpeed(std::size_t i) const;

  // ODE's AABB layout: min x, max x, min y, max y, min z, max z.
  using Aabb = std::array<dReal, 6>;
  /// Contact joints between `body_geom` (whose AABB is `body`) and the
  /// moving solids that reach it.
  void CollideMoving(dGeomID body_geom, const Aabb& body);
  static bool Overlap(const Aabb& a, const Aabb& b) {
    return a[0] <= b[1] && b[0] <= a[1] && a[2] <= b[3] && b[2] <= a[3] && a[4] <= b[5] &&
           b[4] <= a[5];
  }
  // How far around the body's AABB obstacles are listed as near: the
  // list is redone after the body moved about this far.
  static constexpr double kNearMarginM = 0.5;

  struct Carried {
    dGeomID geom = nullptr;
    int belt = 0;
    double x0_m = 0.0, y0_m = 0.0, z_m = 0.0;
    Aabb aabb0{};  // at zero travel
    // The belt travel over which it is on the belt (CarriedTravelRange);
    // outside it, it has left the scene.
    double travel_min_m = 0.0, travel_max_m = 0.0;
  };

  dWorldID world_ = nullptr;
  // Each world steps with its own threading object: without one, ODE steps
  // every world through a single process-wide job list, and two worlds
  // stepped on two threads (a sweep's runs) corrupt it.
  dThreadingImplementationID threading_ = nullptr;
  dJointGroupID group_ = nullptr;
  dGeomID floor_ = nullptr;
  // The floor's profile; the plane stands at its bound.
  models::SurfaceProfile floor_profile_;
  ContactSurface surface_;
  std::vector<BeltPatch> belts_;
  std::vector<std::array<double, 2>> belt_velocity_mps_;
  // Per belt, the unit vectors along and across its length axis.
  std::vector<std::array<double, 4>> belt_axes_;
  std::vector<dGeomID> geoms_;
  std::vector<dGeomID> body_geoms_;
  double body_mu_ = 0.5;
  std::vector<dGeomID> obstacles_;
  std::vector<Aabb> obstacle_aabbs_;
  struct Terrain {
    dGeomID geom = nullptr;
    Aabb aabb{};
    double mu = 0.0;
    // Its top face's profile, and how far its box stands above the
    // nominal top for it (the profile's bound).
    models::SurfaceProfile profile;
    double raise_m = 0.0;
  };
  /// Moves the contact points [from, to) of pts found on surface index s
  /// (as GeomContact) onto its profile; returns the new count (points
  /// without depth dropped, the rest kept in order from `from`).
  int ToUnevenSurface(Points& pts, int from, int to, int s) const;
  std::vector<Terrain> terrain_;
  // The region the near lists hold for (empty at first: min > max), and
  // the obstacles and terrain pieces whose AABB overlaps it.
  Aabb near_region_{1.0, -1.0, 1.0, -1.0, 1.0, -1.0};
  std::vector<std::size_t> near_obstacles_;
  std::vector<std::size_t> near_terrain_;
  std::vector<Carried> carried_;
  // SetMovingSolids: their geoms, values and the time since they were given.
  std::vector<dGeomID> moving_box_geoms_, moving_cylinder_geoms_;
  std::vector<double> moving_boxes_, moving_cylinders_;
  double moving_elapsed_s_ = 0.0;
  int own_box_ = -1;
  std::vector<double> belt_travel_m_;
  // Time since the last SetBeltTravel (substeps of one step).
  double travel_elapsed_s_ = 0.0;
  // ERP and CFM of the object contacts in the current CollideObjects.
  double object_erp_ = 0.0, object_cfm_ = 0.0;
  std::vector<GeomContact> contacts_;
  std::vector<Points> points_;
  std::vector<Tread> treads_;
  std::vector<TreadState> tread_states_;
  // Whether points_ hold the current positions of every geom (a Probe or
  // Step since the last AddGeom, ClearGeoms or SetBelts).
  bool collided_ = false;
};

}  // namespace linesim::chassis
