#include "octomap_io.hpp"

#include <octomap/OcTree.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <sstream>

namespace tomomap {

namespace {

/// octomap's trees have 16 levels below the root (OcTreeKey's 16 bits): the
/// leaves at level 16 have no children.
constexpr int kTreeDepth = 16;

/// The first problem with `data` from `begin` as a serialised tree, found by
/// walking it the way octomap's readers will (OcTree::readBinaryData: 2 bytes
/// a node, 2 bits a child, "11" a child with children of its own;
/// readData: a float log-odds and a byte of children a node), but without
/// recursion: octomap's readers recurse without a bound and read on past the
/// end of a short stream, so 200 kB of 0xff took a daemon's stack. Trailing
/// bytes are left alone, as octomap leaves them. nullopt: a whole tree.
std::optional<std::string> treeDataProblem(const std::string& data, size_t begin, bool binary) {
  const size_t node_bytes = binary ? 2 : sizeof(float) + 1;
  // A node that is read lies at most this deep: in binary data only inner
  // nodes are, leaves being two bits of their parent.
  const int deepest = binary ? kTreeDepth - 1 : kTreeDepth;
  std::vector<int> pending{0};  // depths of the nodes still to read, the next last
  size_t at = begin;
  while (!pending.empty()) {
    const int depth = pending.back();
    pending.pop_back();
    if (depth > deepest) return "nodes below the tree's " + std::to_string(kTreeDepth) + " levels";
    if (data.size() - at < node_bytes) return std::string("it ends inside a node (truncated)");
    bool read_child[8];
    for (int i = 0; i < 8; ++i) {
      if (binary) {
        const auto byte = static_cast<unsigned char>(data[at + (i < 4 ? 0 : 1)]);
        read_child[i] = ((byte >> (2 * (i % 4))) & 3u) == 3u;
      } else {
        read_child[i] = ((static_cast<unsigned char>(data[at + sizeof(float)]) >> i) & 1u) != 0;
      }
    }
    at += node_bytes;
    for (int i = 7; i >= 0; --i)  // read in order 0 to 7
      if (read_child[i]) pending.push_back(depth + 1);
  }
  return std::nullopt;
}

/// `data` from `begin` read into `tree` by octomap's own reader, once it is
/// known to be a whole tree; `what` names it in errors.
void readTreeData(octomap::AbstractOcTree& tree, const std::string& data, size_t begin, bool binary,
                  const std::string& what) {
  if (const auto problem = treeDataProblem(data, begin, binary))
    throw InputError(what + " is not a tree of type " + tree.getTreeType() + ": " + *problem);
  std::istringstream in(data);
  in.seekg(static_cast<std::streamoff>(begin));
  const bool ok = binary ? static_cast<bool>(static_cast<octomap::OcTree&>(tree).readBinaryData(in))
                         : static_cast<bool>(tree.readData(in));
  if (!ok) throw InputError(what + " is not a tree of type " + tree.getTreeType());
}

/// An empty tree of type `id` at `resolution`, as octomap makes it for a
/// file or a message; InputError if it is none or not an OcTree.
std::unique_ptr<octomap::AbstractOcTree> emptyTree(const std::string& id, double resolution,
                                                   const std::string& what) {
  if (!(resolution > 0) || !std::isfinite(resolution))
    throw InputError(what + " gives a resolution of " + std::to_string(resolution) + " m");
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::createTree(id, resolution));
  if (!tree) throw InputError(what + " holds a tree of type '" + id + "', which octomap does not know");
  if (!dynamic_cast<octomap::OcTree*>(tree.get())) throw InputError(what + " holds a " + id + ", not an OcTree (occupancy)");
  return tree;
}

/// An OctoMap file's tree: the header octomap's readHeader reads (its first
/// line, then keywords until "data"), then the tree's data.
std::unique_ptr<octomap::AbstractOcTree> readTreeFile(const std::string& path, bool binary) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open");
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const std::string first_line = binary ? "# Octomap OcTree binary file" : "# Octomap OcTree file";
  const std::string kind = binary ? "OctoMap binary tree (.bt)" : "OctoMap tree (.ot)";
  if (bytes.compare(0, first_line.size(), first_line) != 0) throw InputError(path + ": not a readable " + kind);
  std::istringstream in(bytes);
  std::string token, id = binary ? "OcTree" : "";
  double resolution = 0;
  std::getline(in, token);
  while (in >> token && token != "data") {
    if (token == "id")
      in >> id;
    else if (token == "res")
      in >> resolution;
    std::getline(in, token);  // the rest of the line: a comment, a size, a keyword octomap skips
  }
  if (token != "data") throw InputError(path + ": not a readable " + kind + " (no data)");
  std::getline(in, token);  // the data starts on the next line
  if (!in) throw InputError(path + ": not a readable " + kind + " (no data)");
  auto tree = emptyTree(id, resolution, path);
  readTreeData(*tree, bytes, static_cast<size_t>(in.tellg()), binary, path);
  return tree;
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

Points loadOctomap(const std::string& path, bool binary) {
  const auto tree = readTreeFile(path, binary);
  return occupiedCentres(static_cast<const octomap::OcTree*>(tree.get()), path);
}

Points octomapFromMessage(bool binary, const std::string& id, double resolution, const std::vector<uint8_t>& data) {
  const std::string what = "the Octomap message";
  // Binary messages hold occupancy alone: an OcTree, whatever `id` says.
  auto tree = emptyTree(binary ? "OcTree" : id, resolution, what);
  readTreeData(*tree, std::string(data.begin(), data.end()), 0, binary, what);
  return occupiedCentres(static_cast<const octomap::OcTree*>(tree.get()), what);
}

}  // namespace tomomap
