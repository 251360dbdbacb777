#include "weft/volume/grid_io.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <string>

#include <openvdb/io/File.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {

namespace {

/// Reads a .vdb file's structure (OpenVDB file format 211–224: io::Archive::readHeader,
/// MetaMap::readMeta, GridDescriptor::read) without allocating anything the file declares,
/// checking every declared string length, byte count and grid offset against the bytes that
/// are actually there. OpenVDB's reader does not: a length read past the end of a truncated
/// file is an uninitialised integer, and `std::string(size, ' ')` then allocates gigabytes.
class VdbScanner {
 public:
  VdbScanner(const std::filesystem::path& path, std::istream& in, std::uint64_t size)
      : where_(path.string()), in_(in), size_(size) {}

  void check() {
    const auto magic = read<std::int64_t>("magic number");
    if (magic != openvdb::OPENVDB_MAGIC)
      fail("{}: cannot read OpenVDB file: not a .vdb file (bad magic number)", where_);
    version_ = read<std::uint32_t>("file version");
    if (version_ < 211 || version_ > 1000)
      fail("{}: cannot read OpenVDB file: unsupported file version {}", where_, version_);
    skip(8, "library version");
    const auto has_offsets = read<char>("header");
    if (!has_offsets) fail("{}: cannot read OpenVDB file: no grid offsets (format too old)", where_);
    if (version_ >= openvdb::OPENVDB_FILE_VERSION_SELECTIVE_COMPRESSION &&
        version_ < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION)
      skip(1, "compression flag");
    skip(version_ >= openvdb::OPENVDB_FILE_VERSION_BOOST_UUID ? 36 : 16, "UUID");
    meta_map("file metadata", size_);
    const auto grids = read<std::int32_t>("grid count");
    if (grids < 0) fail("{}: cannot read OpenVDB file: negative grid count {}", where_, grids);
    for (std::int32_t i = 0; i < grids; ++i) grid(i);
  }

 private:
  template <typename T>
  T read(const char* what) {
    T value{};
    if (size_ - position() < sizeof(T)) truncated(what);
    in_.read(reinterpret_cast<char*>(&value), sizeof(T));
    if (!in_) truncated(what);
    return value;
  }

  std::uint64_t position() { return static_cast<std::uint64_t>(in_.tellg()); }

  [[noreturn]] void truncated(const char* what) {
    fail("{}: cannot read OpenVDB file: truncated ({} bytes; {} cut short)", where_, size_, what);
  }

  void skip(std::uint64_t bytes, const char* what, std::uint64_t limit = 0) {
    if (limit == 0) limit = size_;
    if (bytes > limit - std::min(limit, position())) truncated(what);
    in_.seekg(static_cast<std::streamoff>(bytes), std::ios::cur);
  }

  /// A length-prefixed string (io::readString): returns it only if short, else skips it.
  std::string string(const char* what, std::uint64_t limit) {
    const auto length = read<std::uint32_t>(what);
    if (length > limit - std::min(limit, position())) truncated(what);
    if (length > 256) {
      skip(length, what, limit);
      return {};
    }
    std::string text(length, '\0');
    in_.read(text.data(), length);
    if (!in_) truncated(what);
    return text;
  }

  /// MetaMap::readMeta: a count, then name, type name and a byte-counted value per item.
  void meta_map(const char* what, std::uint64_t limit) {
    const auto count = read<std::uint32_t>(what);
    // Each item takes at least 12 bytes (three lengths).
    if (count > (limit - std::min(limit, position())) / 12) truncated(what);
    for (std::uint32_t i = 0; i < count; ++i) {
      (void)string(what, limit);
      const std::string type = string(what, limit);
      const auto bytes = read<std::uint32_t>(what);
      if (bytes > limit - std::min(limit, position())) truncated(what);
      if (type == "__delayedloadmeta" && bytes >= 4) {
        // DelayedLoadMetadata::readValue sizes two arrays by a count it reads from the value.
        const auto entries = read<std::uint32_t>(what);
        if (entries > bytes)
          fail("{}: cannot read OpenVDB file: corrupt ({} declares {} entries in {} bytes)", where_, what, entries,
               bytes);
        skip(bytes - 4, what, limit);
      } else {
        skip(bytes, what, limit);
      }
    }
  }

  /// GridDescriptor::read, then the grid's own header at its offset (compression flags,
  /// metadata, transform type), then on to the next descriptor at the grid's end offset.
  void grid(std::int32_t index) {
    (void)string("grid name", size_);
    (void)string("grid type", size_);
    if (version_ >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING) (void)string("grid instance parent", size_);
    const auto grid_pos = read<std::int64_t>("grid offsets");
    const auto block_pos = read<std::int64_t>("grid offsets");
    const auto end_pos = read<std::int64_t>("grid offsets");
    const auto here = static_cast<std::int64_t>(position());
    if (!(here <= grid_pos && grid_pos <= block_pos && block_pos <= end_pos)) {
      fail("{}: cannot read OpenVDB file: corrupt (grid {} has offsets {}, {}, {})", where_, index, grid_pos, block_pos,
           end_pos);
    }
    if (static_cast<std::uint64_t>(end_pos) > size_) {
      fail("{}: cannot read OpenVDB file: truncated ({} bytes; grid {} ends at byte {})", where_, size_, index,
           end_pos);
    }
    const auto end = static_cast<std::uint64_t>(end_pos);
    in_.seekg(grid_pos);
    if (version_ >= openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) skip(4, "grid compression", end);
    meta_map("grid metadata", end);
    (void)string("grid transform", end);
    in_.seekg(end_pos);
  }

  std::string where_;
  std::istream& in_;
  std::uint64_t size_;
  std::uint32_t version_ = 0;
};

}  // namespace

void check_vdb_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) fail("{}: cannot read OpenVDB file: {}", path.string(), ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("{}: cannot open OpenVDB file", path.string());
  VdbScanner(path, in, size).check();
}

void save_grids(const std::vector<Grid>& grids, const std::filesystem::path& path) {
  ensure_openvdb_initialized();
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      openvdb::GridPtrVec out;
      for (const auto& g : grids) out.push_back(g.impl().grid);
      openvdb::io::File file(tmp.string());
      file.write(out);
      file.close();
    } catch (const openvdb::Exception& e) {
      fail("{}: cannot write OpenVDB file: {}", path.string(), e.what());
    }
  });
}

}  // namespace weft::volume
