#include "pcd_check.hpp"

#include <fcntl.h>
#include <lzf.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <sstream>
#include <vector>

#include "core/huge_pages.hpp"

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

/// The file, mapped read-only for as long as this lives.
class MappedFile {
 public:
  explicit MappedFile(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(path + ": cannot open");
    struct stat st {};
    if (::fstat(fd, &st) == 0 && st.st_size > 0) {
      size_ = static_cast<size_t>(st.st_size);
      void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
      data_ = p == MAP_FAILED ? nullptr : static_cast<const char*>(p);
    }
    ::close(fd);
    if (size_ > 0 && !data_) throw InputError(path + ": cannot read");
  }
  ~MappedFile() { release(); }
  /// Unmaps the file early: its pages count in the process's memory.
  void release() {
    if (data_) ::munmap(const_cast<char*>(data_), size_);
    data_ = nullptr;
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  const char* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  const char* data_ = nullptr;
  size_t size_ = 0;
};

/// Scratch memory for a decompressed map (core/huge_pages.hpp).
class HugeBuffer {
 public:
  explicit HugeBuffer(size_t size) : size_(size), data_(static_cast<char*>(hugeAllocate(size))) {}
  ~HugeBuffer() { hugeFree(data_, size_); }
  HugeBuffer(const HugeBuffer&) = delete;
  HugeBuffer& operator=(const HugeBuffer&) = delete;
  char* get() const { return data_; }

 private:
  size_t size_;
  char* data_;
};

/// What the header says, and where the data starts.
struct PcdHeader {
  std::vector<std::string> fields, types;
  std::vector<long> sizes, counts;
  long points = -1, width = -1, height = 1;
  std::string data;
  size_t data_start = 0;
};

PcdHeader parseHeader(const MappedFile& file) {
  PcdHeader h;
  size_t pos = 0;
  for (int n = 0; n < 64 && h.data.empty() && pos < file.size(); ++n) {
    const char* end = static_cast<const char*>(std::memchr(file.data() + pos, '\n', file.size() - pos));
    const size_t next = end ? static_cast<size_t>(end - file.data()) + 1 : file.size();
    std::istringstream fields(std::string(file.data() + pos, next - pos));
    pos = next;
    std::string key;
    fields >> key;
    if (key == "FIELDS" || key == "TYPE") {
      auto& into = key == "FIELDS" ? h.fields : h.types;
      for (std::string f; fields >> f;) into.push_back(f);
    } else if (key == "SIZE")
      h.sizes = numbers(fields);
    else if (key == "COUNT")
      h.counts = numbers(fields);
    else if (key == "POINTS")
      h.points = numbers(fields).at(0);
    else if (key == "WIDTH")
      h.width = numbers(fields).at(0);
    else if (key == "HEIGHT")
      h.height = numbers(fields).at(0);
    else if (key == "DATA")
      fields >> h.data;
  }
  h.data_start = pos;
  return h;
}

/// Where x, y and z sit in a record (binary) or which block they are (compressed).
struct XyzLayout {
  size_t field[3];
  bool doubles[3];
};

std::optional<XyzLayout> xyzLayout(const PcdHeader& h) {
  XyzLayout l{};
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    size_t f = 0;
    while (f < h.fields.size() && h.fields[f] != axes[a]) ++f;
    if (f == h.fields.size() || h.types[f] != "F" || h.counts[f] != 1 || (h.sizes[f] != 4 && h.sizes[f] != 8))
      return std::nullopt;
    l.field[a] = f;
    l.doubles[a] = h.sizes[f] == 8;
  }
  return l;
}

float readFloat(const char* p, bool as_double) {
  if (as_double) {
    double v;
    std::memcpy(&v, p, sizeof v);
    return static_cast<float>(v);
  }
  float v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

}  // namespace

std::optional<Points> checkAndReadPcd(const std::string& path) {
  MappedFile file(path);
  auto fail = [&](const std::string& why) { throw InputError(path + ": " + why); };
  PcdHeader h = parseHeader(file);
  if (h.data.empty()) fail("not a PCD file (no DATA line in the header)");
  if (h.counts.empty()) h.counts.assign(h.sizes.size(), 1);
  const size_t nf = h.fields.size();
  if (nf == 0 || h.sizes.size() != nf || h.types.size() != nf || h.counts.size() != nf)
    fail("corrupt PCD header (FIELDS, SIZE, TYPE and COUNT disagree)");
  if (h.data == "ascii") return std::nullopt;  // PCL parses text with its own checks
  if (h.points < 0) h.points = h.width * h.height;
  if (h.points < 0) fail("corrupt PCD header (bad POINTS)");
  std::vector<size_t> offset(nf);  // of each field within a record
  long step = 0;
  for (size_t i = 0; i < nf; ++i) {
    if (h.sizes[i] <= 0 || h.counts[i] <= 0) fail("corrupt PCD header (bad SIZE or COUNT)");
    offset[i] = static_cast<size_t>(step);
    step += h.sizes[i] * h.counts[i];
  }
  const long available = static_cast<long>(file.size() - h.data_start);
  const long expected = h.points * step;
  const char* data = file.data() + h.data_start;
  const auto n = static_cast<size_t>(h.points);
  const std::optional<XyzLayout> xyz = xyzLayout(h);

  if (h.data == "binary") {
    if (available < expected)
      fail("truncated: " + std::to_string(h.points) + " points need " + std::to_string(expected) +
           " bytes, file holds " + std::to_string(available));
    if (!xyz) return std::nullopt;
    Points out(n);
    for (size_t i = 0; i < n; ++i) {
      const char* record = data + i * static_cast<size_t>(step);
      for (int a = 0; a < 3; ++a) out[i][a] = readFloat(record + offset[xyz->field[a]], xyz->doubles[a]);
    }
    return out;
  }
  if (h.data != "binary_compressed") fail("unknown PCD DATA type '" + h.data + "'");
  uint32_t packed = 0, unpacked = 0;
  if (available < 8) fail("truncated: compressed data cut short");
  std::memcpy(&packed, data, 4);
  std::memcpy(&unpacked, data + 4, 4);
  if (available < 8 + static_cast<long>(packed)) fail("truncated: compressed data cut short");
  if (static_cast<long>(unpacked) != expected)
    fail("corrupt: compressed data holds " + std::to_string(unpacked) + " bytes, header promises " +
         std::to_string(expected));
  if (packed == 0 && unpacked == 0) return xyz ? std::optional<Points>(Points{}) : std::nullopt;
  const HugeBuffer raw(unpacked);
  if (lzf_decompress(data + 8, packed, raw.get(), unpacked) != unpacked)
    fail("corrupt: compressed data does not decompress");
  file.release();  // before the points are allocated: a map's compressed file no longer beside them
  if (!xyz) return std::nullopt;
  // Compressed PCD data is stored field by field: all x, then all y, ...
  Points out(n);
  for (int a = 0; a < 3; ++a) {
    const size_t f = xyz->field[a];
    const char* block = raw.get() + offset[f] * n;
    const size_t size = static_cast<size_t>(h.sizes[f]);
    for (size_t i = 0; i < n; ++i) out[i][a] = readFloat(block + i * size, xyz->doubles[a]);
  }
  return out;
}

}  // namespace tomomap
