#include "octomap_io.hpp"

#include <octomap/OcTree.h>

#include <cmath>
#include <memory>
#include <sstream>

namespace tomomap {

namespace {

std::unique_ptr<octomap::OcTree> readTree(const std::string& path, bool binary) {
  if (binary) {
    auto tree = std::make_unique<octomap::OcTree>(0.1);  // the file sets the resolution
    if (!tree->readBinary(path)) throw InputError(path + ": not a readable OctoMap binary tree (.bt)");
    return tree;
  }
  std::unique_ptr<octomap::AbstractOcTree> any(octomap::AbstractOcTree::read(path));
  if (!any) throw InputError(path + ": not a readable OctoMap tree (.ot)");
  if (!dynamic_cast<octomap::OcTree*>(any.get()))
    throw InputError(path + ": an OctoMap " + any->getTreeType() + ", not an OcTree (occupancy)");
  return std::unique_ptr<octomap::OcTree>(static_cast<octomap::OcTree*>(any.release()));
}

/// A tree's occupied voxels at its finest resolution; `what` names it in errors.
Points occupiedCentres(const octomap::OcTree* tree, const std::string& what) {
  const double res = tree->getResolution();
  Points out;
  for (auto it = tree->begin_leafs(); it != tree->end_leafs(); ++it) {
    if (!tree->isNodeOccupied(*it)) continue;
    // A pruned leaf covers n^3 voxels of the finest size.
    const auto n = static_cast<size_t>(std::lround(it.getSize() / res));
    if (out.size() + n * n * n > kMaxOctomapPoints)
      throw InputError(what + ": expands to more than " + std::to_string(kMaxOctomapPoints) + " occupied voxels");
    const octomap::point3d c = it.getCoordinate();
    const double first = -0.5 * it.getSize() + 0.5 * res;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        for (size_t k = 0; k < n; ++k)
          out.emplace_back(static_cast<float>(c.x() + first + res * static_cast<double>(i)),
                           static_cast<float>(c.y() + first + res * static_cast<double>(j)),
                           static_cast<float>(c.z() + first + res * static_cast<double>(k)));
  }
  return out;
}

}  // namespace

Points loadOctomap(const std::string& path, bool binary) { return occupiedCentres(readTree(path, binary).get(), path); }

Points octomapFromMessage(bool binary, const std::string& id, double resolution, const std::vector<uint8_t>& data) {
  if (!(resolution > 0) || !std::isfinite(resolution))
    throw InputError("an Octomap message of resolution " + std::to_string(resolution) + " m");
  std::istringstream in(std::string(data.begin(), data.end()));
  std::unique_ptr<octomap::AbstractOcTree> tree;
  if (binary) {
    // Binary messages hold occupancy alone: an OcTree, whatever `id` says.
    auto occupancy = std::make_unique<octomap::OcTree>(resolution);
    if (!occupancy->readBinaryData(in)) throw InputError("an Octomap message whose binary data is not a tree");
    tree = std::move(occupancy);
  } else {
    tree.reset(octomap::AbstractOcTree::createTree(id, resolution));
    if (!tree) throw InputError("an Octomap message of tree type '" + id + "', which octomap does not know");
    if (!dynamic_cast<octomap::OcTree*>(tree.get()))
      throw InputError("an Octomap message of a " + id + ", not an OcTree (occupancy)");
    if (!tree->readData(in)) throw InputError("an Octomap message whose data is not a tree of type " + id);
  }
  return occupiedCentres(static_cast<const octomap::OcTree*>(tree.get()), "the Octomap message");
}

}  // namespace tomomap
