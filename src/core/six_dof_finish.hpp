#pragma once
// A 6-DoF finish of a 4-DoF answer on the two maps' occupied cells: the
// levelling of each map leaves 0.5-3 degrees of roll and pitch between them,
// which a yaw-only answer cannot take up.
#include <string>

#include "slices.hpp"

namespace tomomap {

struct SixDofFinishParams {
  /// Correspondence radius per stage [grid cells]: wide first, so that cells the
  /// 4-DoF answer left a few cells off (0.3-0.7 m at 0.1 m) find their surface,
  /// then narrow, so that only the surface a cell lies on pulls it. The last
  /// radius also counts the inliers the result is judged by.
  std::vector<double> radii_cells{3.0, 1.5};
  /// Gauss-Newton iterations per stage at most [count]; a stage stops earlier once
  /// an update moves the cells less than `converged_cells`.
  int iterations_per_stage = 15;
  /// An update that moves the cells less than this is converged [grid cells]: far
  /// below the quantisation of the cells themselves. At 0.001 the stages ran
  /// to their 15 iterations on the generated buildings at 0.05 m (the
  /// correspondences keep flipping by a cell).
  double converged_cells = 0.02;
  /// Source cells used at most (evenly thinned) [count]: bounds the time;
  /// twenty thousand surface cells fix six parameters many times over. Against
  /// 0.001 cells and 40,000: the SLAM maps' errors (hku-main-building, 16
  /// leaning pairs) changed by at most 4 mm and 0.04 deg, the generated
  /// buildings' and tilted maps' by at most 11 mm (streets' 17-30 mm smaller),
  /// and the finish took 0.13 s instead of 0.34 (median of those 24 pairs).
  size_t max_points = 20000;
  /// Target normals: principal axes of the target cells within this radius
  /// [grid cells]; 2 cells hold ~13 cells of a plane, enough for a stable normal.
  double normal_radius_cells = 2.0;
  /// A neighbourhood is a plane when its smallest spread is at most this share
  /// of its middle one [ratio of eigenvalues]; a plane's voxel staircase reads
  /// ~0.1, a corner or clutter 0.3 and more. Non-planar neighbourhoods are left out.
  double planarity = 0.25;
  /// Geman-McClure kernel scale as a share of the stage's radius [ratio]: cells
  /// farther from their plane than a third of the radius pull less and less.
  double kernel_share = 1.0 / 3.0;
  /// It is a finish, not a search: a result that moved the source's cells by
  /// more than this on average [grid cells] or turned by more than `max_turn`
  /// [rad] is refused. The 4-DoF answer is 0.3-0.7 m off (3-7 cells at 0.1 m)
  /// and the residual roll and pitch 0.5-3 degrees, plus about a degree of yaw.
  double max_move_cells = 8.0;
  double max_turn = radians(5.0);
  /// Fewer inliers than this share of the source cells used, at the start or at
  /// the end, is too little overlap to judge the result by [ratio].
  double min_overlap = 0.1;
  /// A finish that leaves this much fewer of the source's cells on the
  /// target's surfaces than it found [share] fits worse: it keeps the start.
  /// At a pose the finish cannot improve, the share moves by a few cells in
  /// ten thousand (0.1 %) as the cells settle.
  double seen_found_noise = 0.005;
  /// A step leaves alone the directions the surfaces hardly fix: those whose
  /// information (an eigenvalue of the 6 x 6 system, every unknown in metres)
  /// is below this share of the best-fixed one's [ratio]. Along them the
  /// cells' pulls are the maps' own distortions, not the pose: on the
  /// generated streets (facades along one axis) a free finish moved answers
  /// 0.1-0.7 m along the street. At 0.02 the streets' answers moved 0.03 m
  /// farther on average instead of 0.09, and the SLAM maps' lean was taken
  /// up as fully as with none (docs/results.md); at 0.1 the lean was not.
  double min_constraint = 0.02;
  int threads = 1;  ///< threads it uses (MatchParams::threads, resolved); the result does not depend on it
};

struct SixDofFinish {
  bool held = false;    ///< it converged within bounds and the fit did not get worse
  std::string why_not;  ///< when not held: what went wrong, with figures
  Eigen::Matrix4d T_target_source =
      Eigen::Matrix4d::Identity();               ///< the refined transform (== the start when not held)
  double roll_pitch_corrected = 0;               ///< angle between the refined rotation's z axis and the start's [rad]
  double moved = 0;                              ///< mean displacement of the source cells used, start to refined [m]
  double rms_before = 0, rms_after = 0;          ///< point-to-plane rms of the inliers [m]
  size_t inliers_before = 0, inliers_after = 0;  ///< source cells with a planar target cell within the last radius
  /// Of the source cells that land in a column where the target saw anything,
  /// the share that found their surface [ratio]: at the right pose all but the
  /// ones the target did not see; at a wrong one, only those of shared floors.
  double seen_found_before = 0, seen_found_after = 0;
  size_t points = 0;   ///< source cells used (after thinning)
  int iterations = 0;  ///< Gauss-Newton iterations over all stages
};

/// Refines `T_start` (a 4-DoF answer, p_target = T * p_source) in all six
/// degrees of freedom by robust point-to-plane ICP of the source's occupied cell
/// centres against planes fitted to the target's. Keeps the start, with a
/// reason, where the result moved or turned too far, or fits worse than the start.
SixDofFinish finishSixDof(const SliceStack& target, const SliceStack& source, const Eigen::Matrix4d& T_start,
                          const SixDofFinishParams& params = {});

}  // namespace tomomap
