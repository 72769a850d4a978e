#include "pcd_check.hpp"

#include <pcl/io/lzf.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/types.hpp"

namespace tomomap {
namespace {

std::vector<long> numbers(std::istringstream& fields) {
  std::vector<long> v;
  std::string token;
  while (fields >> token) {
    try {
      v.push_back(std::stol(token));
    } catch (const std::exception&) {
      v.push_back(-1);
    }
  }
  return v;
}

}  // namespace

void checkPcdIntegrity(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  auto fail = [&](const std::string& why) { throw InputError(path + ": " + why); };

  std::vector<long> sizes, counts;
  size_t fields_n = 0, types_n = 0;
  long points = -1, width = -1, height = 1;
  std::string data, line;
  for (int n = 0; n < 64 && data.empty() && std::getline(in, line); ++n) {
    std::istringstream fields(line);
    std::string key;
    fields >> key;
    if (key == "FIELDS" || key == "TYPE") {
      size_t& n_of = key == "FIELDS" ? fields_n : types_n;
      for (std::string f; fields >> f;) ++n_of;
    } else if (key == "SIZE")
      sizes = numbers(fields);
    else if (key == "COUNT")
      counts = numbers(fields);
    else if (key == "POINTS")
      points = numbers(fields).at(0);
    else if (key == "WIDTH")
      width = numbers(fields).at(0);
    else if (key == "HEIGHT")
      height = numbers(fields).at(0);
    else if (key == "DATA")
      fields >> data;
  }
  if (data.empty()) fail("not a PCD file (no DATA line in the header)");
  if (counts.empty()) counts.assign(sizes.size(), 1);
  if (fields_n == 0 || sizes.size() != fields_n || types_n != fields_n || counts.size() != fields_n)
    fail("corrupt PCD header (FIELDS, SIZE, TYPE and COUNT disagree)");
  if (data == "ascii") return;  // PCL parses text with its own checks
  if (points < 0) points = width * height;
  if (points < 0) fail("corrupt PCD header (bad POINTS)");
  long step = 0;
  for (size_t i = 0; i < sizes.size(); ++i) {
    if (sizes[i] <= 0 || counts[i] <= 0) fail("corrupt PCD header (bad SIZE or COUNT)");
    step += sizes[i] * counts[i];
  }
  const auto data_start = static_cast<long>(in.tellg());
  in.seekg(0, std::ios::end);
  const long available = static_cast<long>(in.tellg()) - data_start;
  const long expected = points * step;

  if (data == "binary") {
    if (available < expected)
      fail("truncated: " + std::to_string(points) + " points need " + std::to_string(expected) + " bytes, file holds " +
           std::to_string(available));
    return;
  }
  if (data != "binary_compressed") fail("unknown PCD DATA type '" + data + "'");
  uint32_t packed = 0, unpacked = 0;
  in.seekg(data_start);
  in.read(reinterpret_cast<char*>(&packed), 4);
  in.read(reinterpret_cast<char*>(&unpacked), 4);
  if (!in || available < 8 + static_cast<long>(packed)) fail("truncated: compressed data cut short");
  if (static_cast<long>(unpacked) != expected)
    fail("corrupt: compressed data holds " + std::to_string(unpacked) + " bytes, header promises " +
         std::to_string(expected));
  if (packed == 0 && unpacked == 0) return;
  std::vector<char> src(packed), dst(unpacked);
  in.read(src.data(), packed);
  if (!in || pcl::lzfDecompress(src.data(), packed, dst.data(), unpacked) != unpacked)
    fail("corrupt: compressed data does not decompress");
}

}  // namespace tomomap
