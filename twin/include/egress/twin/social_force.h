#pragma once
/// @file
/// Our Social Force Model for people (Helbing & Molnár 1995 social and wall repulsion, with the
/// body compression and sliding friction of Helbing, Farkas & Vicsek 2000 when bodies touch;
/// constants from social_sim_notes §1.1). Planar, in W, independent of physics: the twin moves
/// kinematic capsules to the positions it integrates. A social term below 1e-3 of its value at
/// contact is dropped (HM95's b beyond σ ln 1000, 2.1 m), so that a walker meets only the
/// walkers within a few metres of it (Step's cell lists), whatever the crowd's size.

#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace egress::twin {

struct SocialForceParams {
  double relaxation_time{0.5};  ///< τ [s]
  double drive_factor{2.0};     ///< Gain on the driving term (lightsfm's desired-force
                                ///< factor): lets walkers through 1 m doorways
  double social_strength{2.1};  ///< V0 [m²/s²] (HM95)
  double social_range{0.3};     ///< σ [m]
  double social_horizon{2.0};   ///< Δt of the step ellipse [s]
  /// U0 [m²/s²] on the surface gap. HM95 uses 10 on the centre distance, which stops walkers
  /// at the jambs of a 1 m ADA doorway; 2 lets them pass while still keeping off walls.
  double wall_strength{2.0};
  double wall_range{0.2};           ///< R [m]
  double body_compression{1.2e5};   ///< k [kg/s²] (HFV00)
  double sliding_friction{2.4e5};   ///< κ [kg/(m·s)]
  double mass{80.0};                ///< [kg]
  double behind_weight{0.5};        ///< c: weight of forces from outside the field of view
  double field_of_view_deg{200.0};  ///< 2φ
  double max_speed_factor{1.3};     ///< v_max = factor · v0
  double robot_strength{6.0};       ///< Repulsion from a disc obstacle (the robot) [m²/s²]:
                                    ///< people keep more room from a robot than HM95's 2.1
  double robot_range{0.4};          ///< [m]
  /// Deceleration [m/s²] a walker keeps in hand towards a disc (the robot): its speed towards
  /// the disc, relative to the disc's, is capped at sqrt(2 · this · (gap − disc_keep_gap)), so
  /// it could stop short of it (Tordeux et al. 2016's collision-free speed, along one
  /// direction). People see a robot ahead and do not walk into it, whatever the crowd behind
  /// them does; only their own approach is capped (a disc driving at them still touches).
  double disc_braking_deceleration{2.0};
  double disc_keep_gap{0.05};     ///< Surface gap [m] a walker stops short of a disc by
  double keep_right{0.3};         ///< Share of the social force turned to the walker's right
                                  ///< to break head-on symmetry [–]
  double max_acceleration{20.0};  ///< Clamp [m/s²] (the contact terms are stiff)
};

/// One walker's state in W.
struct Walker {
  Eigen::Vector2d position{Eigen::Vector2d::Zero()};
  Eigen::Vector2d velocity{Eigen::Vector2d::Zero()};
  double radius{0.25};
  double desired_speed{1.3};                        ///< v0 [m/s]; 0 = stand still
  Eigen::Vector2d target{Eigen::Vector2d::Zero()};  ///< Current waypoint
  bool final_target{true};  ///< Slow down to stop at the target (false: a via point)
  /// τ of this walker [s]; 0: the model's. A slow walker (a wheelchair, a frame) pushes as hard
  /// as anyone, only to a lower top speed: with the model's τ its drive, ∝ v0, would lose to the
  /// walls' push short of a doorway.
  double relaxation_time{0.0};
  /// Scale of the walls' social push on this walker [-]: a wide body (a wheelchair) keeps less
  /// room from walls than a walker does, or it would never pass a 1 m ADA doorway (both jambs
  /// push it back). Body compression at contact is not scaled.
  double wall_scale{1.0};
  /// Held where it stands (a person not yet set off): it acts on the others as any walker does,
  /// but no force moves it (its acceleration is zero, not summed, and Integrate leaves it; its
  /// social terms alone, CalcSocialAccelerations, are summed: they are held between sums).
  bool held{false};
};

/// A disc that walkers avoid but the model does not move (the robot).
struct DiscObstacle {
  Eigen::Vector2d position{Eigen::Vector2d::Zero()};
  Eigen::Vector2d velocity{Eigen::Vector2d::Zero()};
  double radius{0.215};
};

/// A wall segment in W. Segments with the same `obstacle` id (≥ 0) outline one obstacle, which
/// repels from its nearest point only (so a corner shared by two segments counts once).
struct WallSegment {
  Eigen::Vector2d a{Eigen::Vector2d::Zero()};
  Eigen::Vector2d b{Eigen::Vector2d::Zero()};
  int obstacle{-1};
};

/// Closest point to p on segment ab.
Eigen::Vector2d ClosestPointOnSegment(const Eigen::Vector2d& p, const WallSegment& s);

/// Whether segments ab and cd cross; touching counts.
bool SegmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d);

/// Walls binned in a uniform grid (a cell list) so that a walker meets only the segments within
/// the model's wall reach. Built once for the walls that do not move (a building's).
class WallCells {
 public:
  WallCells() = default;
  /// Lists, for each cell, every segment within `reach` [m] of it: at least the model's
  /// SocialForceModel::WallReach() (the default is for the default parameters).
  explicit WallCells(std::vector<WallSegment> walls, double reach = kDefaultReachM);
  /// The reach of SocialForceModel's default parameters [m].
  static constexpr double kDefaultReachM = 2.4;

  double reach() const { return reach_; }

  const std::vector<WallSegment>& walls() const { return walls_; }
  /// Indices into walls() of every segment within the wall reach of p (and maybe a few more),
  /// ascending.
  const std::vector<std::size_t>& Near(const Eigen::Vector2d& p) const;
  /// The same within touching distance of p (a body there may press against them): a subset.
  const std::vector<std::size_t>& NearTouching(const Eigen::Vector2d& p) const;
  /// Per wall: the index of the first wall of its obstacle (the order obstacles are summed).
  const std::vector<std::size_t>& rank() const { return rank_; }

 private:
  std::vector<WallSegment> walls_;
  double reach_{kDefaultReachM};
  std::vector<std::size_t> rank_;
  std::map<std::pair<long, long>, std::vector<std::size_t>> cells_;
  std::map<std::pair<long, long>, std::vector<std::size_t>> touching_cells_;
  std::vector<std::size_t> none_;
};

class SocialForceModel {
 public:
  explicit SocialForceModel(SocialForceParams params = {})
      : params_(params), cos_half_fov_(std::cos(params.field_of_view_deg * M_PI / 360.0)) {}

  /// Acceleration of walker i [m/s²] from its goal, the other walkers, discs and walls.
  Eigen::Vector2d CalcAcceleration(std::size_t i, const std::vector<Walker>& walkers,
                                   const std::vector<DiscObstacle>& discs,
                                   const std::vector<WallSegment>& walls) const;
  /// Advances every walker by dt [s] (semi-implicit Euler, speed clipped to v_max).
  void Step(std::vector<Walker>* walkers, const std::vector<DiscObstacle>& discs,
            const std::vector<WallSegment>& walls, double dt) const;
  /// The same, with the walls that do not move binned beforehand (`fixed`) and those that do
  /// (door leaves) given as `moving`: the same sums as Step over fixed.walls() then `moving`.
  void Step(std::vector<Walker>* walkers, const std::vector<DiscObstacle>& discs,
            const WallCells& fixed, const std::vector<WallSegment>& moving, double dt) const;

  /// Every walker's acceleration [m/s²]: what the Step above integrates, the same sums.
  std::vector<Eigen::Vector2d> CalcAccelerations(const std::vector<Walker>& walkers,
                                                 const std::vector<DiscObstacle>& discs,
                                                 const WallCells& fixed,
                                                 const std::vector<WallSegment>& moving) const;
  /// The slowly varying part of every walker's acceleration [m/s²]: the other walkers' and the
  /// discs' social repulsion and the walls' (HM95's exponential terms). A caller may hold it
  /// over several steps and pass it to CalcAccelerationsWithSocial each step: these terms change
  /// over the tenths of a second people take to close a social range, and they are most of a
  /// crowd's cost (an exp and three square roots per pair within ~2 m).
  std::vector<Eigen::Vector2d> CalcSocialAccelerations(
      const std::vector<Walker>& walkers, const std::vector<DiscObstacle>& discs,
      const WallCells& fixed, const std::vector<WallSegment>& moving) const;
  /// Every walker's acceleration [m/s²] with its social part taken from `social` (one per walker,
  /// from CalcSocialAccelerations, maybe a few steps old) and the rest summed now: the drive
  /// towards the target and body contact with walkers, discs and walls, which are stiff (held
  /// over steps they let bodies sink into each other and jam a doorway).
  /// @throws InvalidArgument when `social` does not hold one per walker.
  std::vector<Eigen::Vector2d> CalcAccelerationsWithSocial(
      const std::vector<Eigen::Vector2d>& social, const std::vector<Walker>& walkers,
      const std::vector<DiscObstacle>& discs, const WallCells& fixed,
      const std::vector<WallSegment>& moving) const;
  /// Advances every walker by dt [s] under `accelerations` (one per walker), as Step does: a
  /// caller may hold accelerations over several steps (the forces are the costly part).
  /// `discs`: the walkers' approach to each is capped (disc_braking_deceleration).
  void Integrate(std::vector<Walker>* walkers, const std::vector<Eigen::Vector2d>& accelerations,
                 double dt, const std::vector<DiscObstacle>& discs = {}) const;

  const SocialForceParams& params() const { return params_; }
  /// How far from a walker's centre a wall still acts on it, for the largest body [m]: the wall
  /// term is dropped where it is below a thousandth of its value at contact (a gap of
  /// wall_range ln 1000, 1.38 m for HM95's 0.2 m), as the social terms are. WallCells must
  /// list the walls this far from each cell.
  double WallReach() const;

 private:
  // Where walker o's terms can be non-zero: its social term within `social_radius` of
  // `social_centre` (the circle round the HM95 ellipse at the cutoff: centred half its step
  // ahead of it), its body within kMaxBodyReachM of its centre [m].
  struct Reach {
    Eigen::Vector2d social_centre{Eigen::Vector2d::Zero()};
    double social_radius{0.0};
  };
  // Who can reach walker i, from Step's cell lists (nullptr: everyone, everything).
  struct Neighbours {
    const std::vector<std::size_t>* walkers{nullptr};  // indices, ascending
    const std::vector<std::size_t>* walls{nullptr};    // indices; a cell's by wall_rank
    // Per wall: the index of the first wall of its obstacle (the order obstacles are summed).
    const std::vector<std::size_t>* wall_rank{nullptr};
    const std::vector<Reach>* reach{nullptr};  // per walker: WalkerReach
    // Walls past the end of `walls` (index walls.size() + k is moving[k]), each its own
    // obstacle, ranked by that index: door leaves, without copying the building's walls.
    const std::vector<WallSegment>* moving{nullptr};
  };
  Reach WalkerReach(const Walker& o) const;
  Eigen::Vector2d CalcAccelerationAmong(std::size_t i, const std::vector<Walker>& walkers,
                                        const Neighbours& near,
                                        const std::vector<DiscObstacle>& discs,
                                        const std::vector<WallSegment>& walls) const;
  // Which terms a sum takes: all of them, the social (slow) ones, or the contact (stiff) ones.
  enum class Terms { kAll, kSocial, kContact };
  // `start` plus walker i's `terms` among `near` (the drive is not among them).
  Eigen::Vector2d CalcTermsAmong(std::size_t i, const std::vector<Walker>& walkers,
                                 const Neighbours& near, const std::vector<DiscObstacle>& discs,
                                 const std::vector<WallSegment>& walls, Terms terms,
                                 Eigen::Vector2d start) const;
  // The drive towards the walker's target: (desired velocity - velocity) / τ, with its gain.
  Eigen::Vector2d CalcDriveAcceleration(const Walker& w) const;
  Eigen::Vector2d ClampAcceleration(const Eigen::Vector2d& a) const;
  // w's velocity with its approach to d capped (disc_braking_deceleration).
  Eigen::Vector2d CapApproach(const Walker& w, const DiscObstacle& d) const;
  // Every walker's `terms` through the cell lists; kContact adds the drive and `social`'s entry
  // and clamps (as kAll does).
  std::vector<Eigen::Vector2d> SumTerms(const std::vector<Walker>& walkers,
                                        const std::vector<DiscObstacle>& discs,
                                        const WallCells& fixed,
                                        const std::vector<WallSegment>& moving, Terms terms,
                                        const std::vector<Eigen::Vector2d>* social) const;
  Eigen::Vector2d BodyForce(const Walker& w, const Eigen::Vector2d& other_p,
                            const Eigen::Vector2d& other_v, double other_r) const;
  SocialForceParams params_;
  double cos_half_fov_;  ///< cos(field_of_view_deg / 2): once, not per walker and step
};

}  // namespace egress::twin
