#include "gravity.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <tuple>
#include <unordered_map>

#include "lattice.hpp"
#include "text.hpp"

namespace tomomap {
namespace {

/// A cube this many grid cells wide holds enough of a surface to fit its plane,
/// and is small enough that most cubes see one surface only.
constexpr double kPatchCells = 8.0;
constexpr double kMinPatchSide = 0.4;  ///< [m]: below, voxel noise tilts the patches
constexpr size_t kMinPatchPoints = 12;
/// The cubes' edge at `grid` [m].
double cubeSide(double grid) { return std::max(kMinPatchSide, kPatchCells * grid); }
/// Flat: the thinnest extent well below the other two (eigenvalues of the
/// patch's covariance), and the patch not a line.
constexpr double kFlatness = 0.05, kNotALine = 0.2;
constexpr int kRounds = 4;
/// Fewer flat patches than this and a cue (floors, walls) says nothing.
constexpr size_t kMinPatches = 20;
/// Walls tell up only where they face two ways: the scatter's middle
/// eigenvalue at least this share of its largest.
constexpr double kTwoWays = 0.1;
/// Normals (and lines) within this of each other count as one direction's:
/// a floor's patches scatter a few degrees (the hall's by 2-4).
const double kModeCone = radians(10.0);
/// A patch leaning off its kind's fit more than this many times the median is not of that kind.
constexpr double kOutlierLeans = 3.0;
/// Estimates, each in the frame the previous ones levelled (see estimateTilt).
constexpr int kPasses = 3;
/// Points looked at, at most: the large surfaces show in a sample.
constexpr size_t kMaxPoints = 500000;
/// The parts a map is read again as (estimateTilt's uncertainty): halves
/// along this many directions, and sparser sensors keeping one point in 3 and in 10.
constexpr int kCutDirections = 4;
constexpr std::array<size_t, 2> kPartThinnings{3, 10};

struct Patch {
  Eigen::Vector3d normal;
  double weight;
};

/// The points of a map one measurement reads, read where they lie rather
/// than copied (a sample, its turned copy and its parts' copies took 26 MB a
/// map beside the voxel filter's buffers, and their pages' faults were among
/// the slowest matrix pair's costs): every
/// `stride`-th point, and of those, for a half, the ones on one side of
/// `cut` along `along`.
struct Part {
  size_t stride = 1;
  bool half = false;
  Eigen::Vector3f along = Eigen::Vector3f::Zero();
  float cut = 0;
  bool below = true;  ///< the half below `cut`; else the one at or above it
  bool holds(const Eigen::Vector3f& p) const { return !half || (p.dot(along) < cut) == below; }
};

/// Every k-th point of `map`: a few hundred thousand describe the large surfaces.
Part sampleOf(const Points& map) { return {std::max<size_t>(1, map.size() / kMaxPoints)}; }

/// `turn` * `p` summed as Eigen sums it, the first term plus the sum of the
/// other two (its unrolled sum splits three terms as one and two; on x86-64 a
/// Vector3f is shorter than a packet, so it is not vectorised), so that the
/// estimate is the same to the bit as with Eigen's product. Written out
/// because the -O1 sanitizer build called that product for every point.
Eigen::Vector3f turnedBy(const Eigen::Matrix3f& turn, const Eigen::Vector3f& p) {
  const auto row = [&](int r) { return turn(r, 0) * p.x() + (turn(r, 1) * p.y() + turn(r, 2) * p.z()); };
  return {row(0), row(1), row(2)};
}

/// The points in one cube: their sums, enough for their covariance.
struct Sums {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  size_t n = 0;
};
using Cubes = std::unordered_map<uint64_t, Sums>;

/// The points of `part` of `map`, turned by `turn`, binned in cubes of
/// `side` on the lattice moved by `shift` along each axis.
Cubes cubesOf(const Points& map, const Part& part, const Eigen::Matrix3f& turn, double side, float shift = 0) {
  Cubes cubes;
  const bool turned = !turn.isIdentity(0.0f);
  const Eigen::Vector3f moved = Eigen::Vector3f::Constant(shift);  // exact where 0: the same cubes
  for (size_t i = 0; i < map.size(); i += part.stride) {
    if (!part.holds(map[i])) continue;
    const Eigen::Vector3f p = turned ? turnedBy(turn, map[i]) : map[i];
    Sums& s = cubes[latticeKey(Eigen::Vector3f(p + moved), side)];
    const Eigen::Vector3d q = p.cast<double>();
    s.sum += q;
    // The upper triangle alone: the lower one is the same products.
    for (int r = 0; r < 3; ++r)
      for (int c = r; c < 3; ++c) s.outer(r, c) += q(r) * q(c);
    ++s.n;
  }
  return cubes;
}

/// How a cube's points spread: their covariance's eigenvalues (ascending)
/// and directions; none for a cube of too few points to tell.
std::optional<Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>> spreadOf(const Sums& s) {
  if (s.n < kMinPatchPoints) return std::nullopt;
  const double n = static_cast<double>(s.n);
  const Eigen::Vector3d mean = s.sum / n;
  const Eigen::Matrix3d outer = s.outer.selfadjointView<Eigen::Upper>();
  const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  return eig;
}

/// The flat cubes of `part` of `map` turned by `turn` (cubesOf) as patches.
std::vector<Patch> flatPatches(const Points& map, const Part& part, const Eigen::Matrix3f& turn, double side) {
  std::vector<Patch> patches;
  for (const auto& [k, s] : cubesOf(map, part, turn, side)) {
    const auto eig = spreadOf(s);
    if (!eig) continue;
    const Eigen::Vector3d l = eig->eigenvalues();  // ascending
    if (!(l(0) < kFlatness * l(1)) || !(l(1) > kNotALine * l(2))) continue;
    patches.push_back({eig->eigenvectors().col(0).normalized(), static_cast<double>(s.n)});
  }
  return patches;
}

/// The direction of a cube's points where they lie along a line (no plane's
/// middle extent: kNotALine).
std::optional<Eigen::Vector3d> lineOf(const Sums& s) {
  const auto eig = spreadOf(s);
  if (!eig) return std::nullopt;
  const Eigen::Vector3d l = eig->eigenvalues();  // ascending
  if (l(1) > kNotALine * l(2)) return std::nullopt;
  return eig->eigenvectors().col(2).normalized();
}

/// The lines of `part` of `map` in the frame `turn` levels it into (posts,
/// trunks, door frames, the corners where walls meet), and how many of them
/// stand within kClassCone of z. A line counts where the lattice half a cube
/// away sees it too, along the same direction: a plane cut near a cube's
/// edge leaves a sliver that looks like a line in one lattice only (in a
/// frame that turned the hall's walls off the lattice's axes, their slivers
/// stood along z as much as its posts did).
std::pair<size_t, size_t> standingLines(const Points& map, const Part& part, const Eigen::Matrix3f& turn, double side) {
  const float half = 0.5f * static_cast<float>(side);
  const Cubes cubes = cubesOf(map, part, turn, side), shifted = cubesOf(map, part, turn, side, half);
  const Eigen::Vector3f to_shifted = Eigen::Vector3f::Constant(half);
  size_t lines = 0, standing = 0;
  for (const auto& [k, s] : cubes) {
    const auto line = lineOf(s);
    if (!line) continue;
    const Eigen::Vector3f centre = (s.sum / static_cast<double>(s.n)).cast<float>();
    const auto there = shifted.find(latticeKey(Eigen::Vector3f(centre + to_shifted), side));
    if (there == shifted.end()) continue;
    const auto again = lineOf(there->second);
    if (!again || std::abs(again->dot(*line)) < std::cos(kModeCone)) continue;
    ++lines;
    standing += std::abs(line->z()) >= std::cos(kClassCone);
  }
  return {lines, standing};
}

/// One cue's up direction and how tightly its patches agree on it.
struct Cue {
  Eigen::Vector3d up;
  double spread = 0;  ///< rms angle of the patches' normals from what `up` makes them [rad]
  size_t patches = 0;
  /// The standard error of `up` [rad].
  double error() const { return spread / std::sqrt(static_cast<double>(patches)); }
};

/// The weighted scatter sum(w n n^T) / sum(w) of patches' normals, solved.
Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> scatter(const std::vector<Patch>& patches) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  double total = 0;
  for (const auto& p : patches) {
    m += p.weight * p.normal * p.normal.transpose();
    total += p.weight;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(m / total);
  return eig;
}

/// Up from one kind of patch, fitted twice: the second time without the
/// patches that lean off the first fit more than kOutlierLeans times the
/// median (kerbs, car roofs, ramps and stair edges among floors; cars, trees
/// and leaning panels among walls): on vehicle LiDAR they pulled the floors'
/// mean 1-3 degrees off the road's plane fit. Floors and ground face up:
/// their mean normal, the scatter's largest eigenvector. Walls face sideways:
/// the direction their normals avoid, its smallest; walls that all face one
/// way (a corridor) leave it free to turn about their normal: no cue then.
std::optional<Cue> fitUp(std::vector<Patch> patches, bool floors) {
  // How far a patch leans off the fit: the angle of its normal from up
  // (floors) or from the horizontal (walls), as its sine or cosine.
  const auto lean = [floors](const Patch& p, const Eigen::Vector3d& up) {
    const double c = std::min(1.0, std::abs(p.normal.dot(up)));
    return floors ? std::acos(c) : std::asin(c);
  };
  for (int fit = 0;; ++fit) {
    if (patches.size() < kMinPatches) return std::nullopt;
    const auto eig = scatter(patches);
    const Eigen::Vector3d l = eig.eigenvalues();  // ascending
    if (!floors && !(l(1) > kTwoWays * l(2))) return std::nullopt;
    const Eigen::Vector3d up = eig.eigenvectors().col(floors ? 2 : 0).normalized();
    const double off = floors ? 1.0 - l(2) : l(0);  // the squared sine of the normals' rms lean
    if (fit == 1) return Cue{up, std::asin(std::min(1.0, std::sqrt(std::max(0.0, off)))), patches.size()};
    std::vector<double> leans;
    for (const auto& p : patches) leans.push_back(lean(p, up));
    std::nth_element(leans.begin(), leans.begin() + static_cast<long>(leans.size() / 2), leans.end());
    const double most = kOutlierLeans * leans[leans.size() / 2];
    patches.erase(std::remove_if(patches.begin(), patches.end(), [&](const Patch& p) { return lean(p, up) > most; }),
                  patches.end());
  }
}

/// Up from the patches, sorted into floors and walls by the up found so far
/// (from `up`, in a few rounds): from the floors, or from the walls where
/// there are too few floors. Floors are the gravity cue: in real maps walls
/// lean a degree or three each way while floors lie level, and on vehicle
/// LiDAR the walls' fit (cars, trees, poles) read 4-6 degrees where the
/// road's plane fit read 1.5.
std::optional<Cue> upOf(const std::vector<Patch>& patches, Eigen::Vector3d up, Tilt& t) {
  const double floor_cos = std::cos(kClassCone), wall_cos = std::sin(kClassCone);
  std::optional<Cue> found;
  for (int round = 0; round < kRounds; ++round) {
    std::vector<Patch> floors, walls;
    for (const auto& p : patches) {
      const double c = std::abs(p.normal.dot(up));
      if (c >= floor_cos)
        floors.push_back(p);
      else if (c <= wall_cos)
        walls.push_back(p);
    }
    t.floor_patches = floors.size();
    t.wall_patches = walls.size();
    t.cue = Tilt::Cue::floors;
    found = fitUp(std::move(floors), true);
    if (!found) {
      t.cue = Tilt::Cue::walls;
      found = fitUp(std::move(walls), false);
    }
    if (!found) return std::nullopt;
    up = found->up.z() < 0 ? Eigen::Vector3d(-found->up) : found->up;
    found->up = up;
  }
  return found;
}

/// Up from the patches of a map whose floors lean beyond kClassCone, where
/// the rounds from z find neither floors nor walls facing two ways: the
/// rounds from the patches' densest normal between kClassCone and
/// kMaxLevelable from z (the most patch weight within kModeCone of it),
/// where they find an up beyond kClassCone (one nearer z the rounds from z
/// would have found).
std::optional<Cue> upBeyondTheCone(const std::vector<Patch>& patches, Tilt& t) {
  const double cone_cos = std::cos(kClassCone), limit_cos = std::cos(kMaxLevelable), mode_cos = std::cos(kModeCone);
  double most = 0;
  std::optional<Eigen::Vector3d> densest;
  for (const Patch& p : patches) {
    const double c = std::abs(p.normal.z());
    if (c >= cone_cos || c < limit_cos) continue;
    double weight = 0;
    for (const Patch& q : patches) weight += std::abs(p.normal.dot(q.normal)) >= mode_cos ? q.weight : 0.0;
    if (weight > most) most = weight, densest = p.normal.z() < 0 ? Eigen::Vector3d(-p.normal) : p.normal;
  }
  if (!densest) return std::nullopt;
  auto found = upOf(patches, *densest, t);
  if (found && found->up.z() >= cone_cos) return std::nullopt;
  return found;
}

/// The estimate itself (see estimateTilt): `up` from the flat patches of
/// `part` of `map`, measured again in the frame levelled so far; from beyond
/// kClassCone too (upBeyondTheCone) where `may_restart`.
Tilt measureTilt(const Points& map, double grid, const Part& part, bool may_restart) {
  // The cubes are axis-aligned: a leaning floor cut at a cube's top and bottom
  // fits a little flatter than it is (a 10 deg lean read as 9.3). Measured
  // again in the frame levelled so far, the cut runs along the floor.
  Tilt t;
  Eigen::Quaterniond leveling = Eigen::Quaterniond::Identity();
  const double side = cubeSide(grid);
  for (int pass = 0; pass < kPasses; ++pass) {
    const Eigen::Matrix3f turn = leveling.toRotationMatrix().cast<float>();  // as rotatePoints turns
    const std::vector<Patch> patches = flatPatches(map, part, turn, side);
    auto cue = upOf(patches, Eigen::Vector3d::UnitZ(), t);
    if (!cue && pass == 0 && may_restart) {
      cue = upBeyondTheCone(patches, t);
      t.beyond_cone = cue.has_value();
    }
    if (!cue) return t;
    leveling = Eigen::Quaterniond::FromTwoVectors(cue->up, Eigen::Vector3d::UnitZ()) * leveling;
    t.uncertainty = cue->error();
  }
  t.measured = true;
  t.up = (leveling.inverse() * Eigen::Vector3d::UnitZ()).normalized();
  t.angle = std::acos(std::clamp(t.up.z(), -1.0, 1.0));
  t.beyond_cone = t.beyond_cone || t.angle > kClassCone;
  return t;
}

/// The parts of a map the estimate is measured on again: its halves either
/// side of the median along four directions 45 degrees apart (a crop to
/// half, as another robot would map the place), and every third and every
/// tenth point (a sparser sensor). Each part of the sample (sampleOf): a
/// sample holds fewer than 2 kMaxPoints points, so each part is read whole.
std::vector<Part> partsOf(const Points& map) {
  const Part sample = sampleOf(map);
  std::vector<Part> parts;
  std::vector<float> v;
  v.reserve(map.size() / sample.stride + 1);
  for (int k = 0; k < kCutDirections; ++k) {
    const double a = kPi * k / kCutDirections;
    const Eigen::Vector3f along(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.0f);
    v.clear();
    for (size_t i = 0; i < map.size(); i += sample.stride) v.push_back(map[i].dot(along));
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    const float median = v[v.size() / 2];
    for (const bool below : {true, false}) parts.push_back({sample.stride, true, along, median, below});
  }
  for (size_t thinning : kPartThinnings) parts.push_back({sample.stride * thinning});
  return parts;
}

}  // namespace

Tilt estimateTilt(const Points& map, double grid, std::optional<double> matched_within) {
  const Part sample = sampleOf(map);
  Tilt t = measureTilt(map, grid, sample, true);
  if (!t.measured || (matched_within && t.angle <= *matched_within)) return t;
  if (t.beyond_cone && t.angle <= kMaxLevelable) {
    // In the frame the estimate levels the map into, where a lattice's cut
    // runs along the floors (measureTilt).
    const Eigen::Matrix3f turn = t.leveling().toRotationMatrix().cast<float>();
    std::tie(t.lines, t.standing_lines) = standingLines(map, sample, turn, cubeSide(grid));
  }
  t.checked = true;
  // A standard error counts the patches as independent; they are not (a
  // road that slopes, one wall that leans): on the real scans, halves of a
  // map read 0.5-2.5 deg from the whole with standard errors of 0.1-0.3. The
  // uncertainty stated is the farthest a part reads from the whole, of the
  // parts that can check it: read off floors, and holding a fair share of the
  // whole's floors (a half with few of them reads whatever else lies flat
  // there: one half of a SLAM map of a walkway read 12.9 deg where the whole
  // and every other part read 7.5). A map most of whose parts cannot check
  // it is not read better than it leans.
  // The parts are a few cuts of many a robot could make: the farthest of
  // them is widened by the whole's standard error (cuts between them read up
  // to that much farther on the real maps).
  size_t checks = 0;
  double farthest = 0;
  const std::vector<Part> parts = partsOf(map);
  for (const Part& part : parts) {
    // The same estimate a crop of the map would get (one pass from the
    // whole's frame read campus-1's halves 0.1 deg nearer than a crop's own);
    // from beyond the cone only where the whole was read there.
    const Tilt p = measureTilt(map, grid, part, t.beyond_cone);
    if (!fairPart(p, t)) continue;
    ++checks;
    farthest = std::max(farthest, std::acos(std::clamp(p.up.dot(t.up), -1.0, 1.0)));
  }
  t.uncertainty += farthest;
  if (2 * checks < parts.size()) t.uncertainty = std::max(t.uncertainty, t.angle);
  return t;
}

bool fairPart(const Tilt& part, const Tilt& whole) {
  const auto patches = [](const Tilt& t) {
    return static_cast<double>(t.cue == Tilt::Cue::walls ? t.wall_patches : t.floor_patches);
  };
  return part.measured && part.cue == whole.cue && patches(part) >= kFairShare * patches(whole);
}

Tilt givenTilt(const Eigen::Vector3d& up) {
  if (!(up.norm() > 0) || !up.allFinite()) throw InputError("an up direction must be a non-zero vector");
  Tilt t;
  t.measured = true;
  t.cue = Tilt::Cue::given;
  t.up = up.normalized();
  t.angle = std::acos(std::clamp(t.up.z(), -1.0, 1.0));
  return t;
}

bool levelableUp(const Eigen::Vector3d& up) {
  return up.allFinite() && std::abs(up.norm() - 1.0) < 1e-6 && up.z() >= std::cos(kMaxLevelable) - 1e-9;
}

std::string leanText(const Tilt& t) {
  const bool stated = t.checked || t.cue == Tilt::Cue::given;  // else only a standard error, not an uncertainty
  return fixed(degrees(t.angle), 1) + (stated ? " +- " + fixed(degrees(t.uncertainty), 1) : std::string()) +
         " deg from gravity (" +
         (t.cue == Tilt::Cue::given    ? "as given"
          : t.cue == Tilt::Cue::floors ? "read off its floors"
                                       : "read off its walls") +
         ")";
}

bool Tilt::linesStand() const { return lines >= kMinLines && 2 * standing_lines > lines; }

bool Tilt::upTrusted() const { return angle <= kMaxLevelable && (!beyond_cone || linesStand()); }

bool Tilt::levelable() const { return measured && uncertainty < angle && upTrusted(); }

Eigen::Quaterniond Tilt::leveling() const { return levelingOf(up); }

Eigen::Quaterniond levelingOf(const Eigen::Vector3d& up) {
  return Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ());
}

Eigen::Matrix4d levelingMatrix(const Eigen::Vector3d& up) {
  Eigen::Matrix4d R = Eigen::Matrix4d::Identity();
  R.topLeftCorner<3, 3>() = levelingOf(up).toRotationMatrix();
  return R;
}

Eigen::Matrix4d betweenOwnFrames(const Eigen::Matrix4d& T, const Eigen::Vector3d& target_up,
                                 const Eigen::Vector3d& source_up) {
  return levelingMatrix(target_up).transpose() * T * levelingMatrix(source_up);
}

Points rotatePoints(const Points& in, const Eigen::Quaterniond& rotation) {
  const Eigen::Matrix3f r = rotation.toRotationMatrix().cast<float>();
  Points out;
  out.reserve(in.size());
  for (const auto& p : in) out.push_back(r * p);
  return out;
}

}  // namespace tomomap
