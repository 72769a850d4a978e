#include "fpfh_ransac.hpp"

#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/registration/sample_consensus_prerejective.h>

#include <chrono>

#include "core/voxel_filter.hpp"

namespace tomomap::baseline {
namespace {

using Cloud = pcl::PointCloud<pcl::PointNormal>;
using Features = pcl::PointCloud<pcl::FPFHSignature33>;

/// Keypoints with normals and FPFH descriptors of one map.
struct Described {
  Cloud::Ptr keypoints{new Cloud};
  Features::Ptr features{new Features};
};

Described describe(const Points& map, const FpfhParams& p) {
  const double g = p.grid;
  // The usual FPFH-RANSAC pipeline: one voxel-downsampled cloud serves as
  // keypoints and as the surface for normals and descriptors.
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& q : voxelFilter(map, p.keypoint_cells * g)) cloud->push_back({q.x(), q.y(), q.z()});
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::PointNormal> ne;
  if (p.threads > 0) ne.setNumberOfThreads(static_cast<unsigned>(p.threads));
  ne.setRadiusSearch(p.normal_radius_cells * g);
  Cloud with_normals;
  ne.setInputCloud(cloud);
  ne.compute(with_normals);
  Described d;
  for (size_t i = 0; i < cloud->size(); ++i) {
    pcl::PointNormal q = with_normals[i];
    if (!std::isfinite(q.normal_x)) continue;  // too few neighbours for a normal
    q.x = (*cloud)[i].x;
    q.y = (*cloud)[i].y;
    q.z = (*cloud)[i].z;
    d.keypoints->push_back(q);
  }
  pcl::FPFHEstimationOMP<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> fe;
  if (p.threads > 0) fe.setNumberOfThreads(static_cast<unsigned>(p.threads));
  fe.setRadiusSearch(p.feature_radius_cells * g);
  fe.setInputCloud(d.keypoints);
  fe.setInputNormals(d.keypoints);
  fe.compute(*d.features);
  return d;
}

}  // namespace

FpfhResult matchFpfhRansac(const Points& target, const Points& source, const FpfhParams& p) {
  const auto t0 = std::chrono::steady_clock::now();
  FpfhResult r;
  const Described t = describe(target, p), s = describe(source, p);
  const auto t1 = std::chrono::steady_clock::now();
  r.describe_seconds = std::chrono::duration<double>(t1 - t0).count();
  r.target_keypoints = t.keypoints->size();
  r.source_keypoints = s.keypoints->size();
  if (t.keypoints->size() < 3 || s.keypoints->size() < 3) return r;

  pcl::SampleConsensusPrerejective<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> align;
  align.setInputSource(s.keypoints);
  align.setSourceFeatures(s.features);
  align.setInputTarget(t.keypoints);
  align.setTargetFeatures(t.features);
  align.setMaximumIterations(p.max_iterations);
  align.setNumberOfSamples(3);
  align.setCorrespondenceRandomness(5);
  align.setSimilarityThreshold(0.9f);
  align.setMaxCorrespondenceDistance(p.inlier_cells * p.grid);
  align.setInlierFraction(0.1f);
  Cloud aligned;
  align.align(aligned);
  r.converged = align.hasConverged();
  r.T_target_source = Pose4::fromMatrix(align.getFinalTransformation().cast<double>());
  r.inlier_fraction = static_cast<double>(align.getInliers().size()) / static_cast<double>(s.keypoints->size());
  r.ransac_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  return r;
}

}  // namespace tomomap::baseline
