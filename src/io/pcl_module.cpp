// The module itself (pcl_module.hpp): compiled into tomomap_pcl_io.so only.
#include "pcl_module.hpp"

#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <cstring>

namespace tomomap {
namespace {

// PCL reports parse problems on stderr; we report them ourselves, once.
void silencePcl() { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }

/// Reads x, y, z straight out of PCL's blob: no intermediate PointCloud, which
/// for a map of millions of points would hold a third copy in memory.
bool fromBlob(const pcl::PCLPointCloud2& blob, const std::string& path, Points* out, std::string* error) {
  int offset[3];
  uint8_t type[3];
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const int f = pcl::getFieldIndex(blob, axes[a]);
    if (f < 0) {
      *error = path + ": has no '" + axes[a] + "' field";
      return false;
    }
    offset[a] = static_cast<int>(blob.fields[static_cast<size_t>(f)].offset);
    type[a] = blob.fields[static_cast<size_t>(f)].datatype;
    if (type[a] != pcl::PCLPointField::FLOAT32 && type[a] != pcl::PCLPointField::FLOAT64) {
      *error = path + ": field '" + axes[a] + "' is not a float";
      return false;
    }
  }
  const size_t n = static_cast<size_t>(blob.width) * blob.height;
  if (blob.point_step == 0 || blob.data.size() < n * blob.point_step) {
    *error = path + ": truncated (header declares " + std::to_string(n) + " points)";
    return false;
  }
  out->resize(n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = blob.data.data() + i * blob.point_step;
    for (int a = 0; a < 3; ++a) {
      if (type[a] == pcl::PCLPointField::FLOAT32) {
        float v;
        std::memcpy(&v, p + offset[a], sizeof v);
        (*out)[i][a] = v;
      } else {
        double v;
        std::memcpy(&v, p + offset[a], sizeof v);
        (*out)[i][a] = static_cast<float>(v);
      }
    }
  }
  return true;
}

bool load(const std::string& path, bool ply, Points* out, std::string* error) try {
  silencePcl();
  pcl::PCLPointCloud2 blob;
  const int rc = ply ? pcl::io::loadPLYFile(path, blob) : pcl::io::loadPCDFile(path, blob);
  if (rc < 0) {
    *error = path + ": not a readable " + (ply ? "PLY" : "PCD") + " file (corrupt or truncated)";
    return false;
  }
  return fromBlob(blob, path, out, error);
} catch (const std::exception& e) {
  *error = path + ": " + e.what();
  return false;
}

bool savePcd(const std::string& path, const Points& points, bool compressed, std::string* error) try {
  silencePcl();
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.reserve(points.size());
  for (const auto& p : points) cloud.push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  if (cloud.empty() ||
      (compressed ? pcl::io::savePCDFileBinaryCompressed(path, cloud) : pcl::io::savePCDFileBinary(path, cloud)) < 0) {
    *error = path + ": cannot write map";
    return false;
  }
  return true;
} catch (const std::exception& e) {
  *error = path + ": cannot write map: " + e.what();
  return false;
}

bool saveLabelledPcd(const std::string& path, const Points& points, const std::vector<uint32_t>& labels,
                     const std::vector<uint32_t>& colours, std::string* error) try {
  silencePcl();
  pcl::PointCloud<pcl::PointXYZRGBL> cloud;
  cloud.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    pcl::PointXYZRGBL p;
    p.x = points[i].x();
    p.y = points[i].y();
    p.z = points[i].z();
    p.label = labels.at(i);
    p.rgba = 0xff000000u | colours.at(labels[i]);
    cloud.push_back(p);
  }
  if (cloud.empty() || pcl::io::savePCDFileBinary(path, cloud) < 0) {
    *error = path + ": cannot write map";
    return false;
  }
  return true;
} catch (const std::exception& e) {
  *error = path + ": cannot write map: " + e.what();
  return false;
}

constexpr PclIo kFunctions{&load, &savePcd, &saveLabelledPcd};

}  // namespace
}  // namespace tomomap

extern "C" __attribute__((visibility("default"))) const tomomap::PclIo* tomomap_pcl_io(unsigned version) {
  return version == tomomap::kPclIoVersion ? &tomomap::kFunctions : nullptr;
}
