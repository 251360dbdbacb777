#include "weft/volume/grid_io.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <openvdb/io/Archive.h>
#include <openvdb/io/Compression.h>
#include <openvdb/io/File.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/file_kind.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {

namespace {

/// The whole file mapped read-only (an empty file maps to no bytes).
class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& path) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) fail("{}: cannot read OpenVDB file: {}", path.string(), ec.message());
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) fail("{}: cannot open OpenVDB file", path.string());
    if (size > 0) {
      void* data = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
      if (data == MAP_FAILED) {
        ::close(fd);
        fail("{}: cannot read OpenVDB file: cannot map {} bytes", path.string(), size);
      }
      data_ = static_cast<const unsigned char*>(data);
      size_ = size;
    }
    ::close(fd);
  }
  ~MappedFile() {
    if (data_) ::munmap(const_cast<unsigned char*>(data_), size_);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  const unsigned char* data() const { return data_; }
  std::uint64_t size() const { return size_; }

 private:
  const unsigned char* data_ = nullptr;
  std::uint64_t size_ = 0;
};

/// Fixed value sizes of OpenVDB's metadata types (TypedMetadata<T>::readValue reads sizeof(T)
/// bytes whatever byte count the file declares, so a different count would desynchronise it).
std::uint32_t fixed_metadata_size(std::string_view type) {
  static constexpr std::pair<std::string_view, std::uint32_t> sizes[] = {
      {"bool", 1},        {"half", 2},       {"float", 4},  {"double", 8},  {"int8", 1},    {"uint8", 1},
      {"int16", 2},       {"uint16", 2},     {"int32", 4},  {"uint32", 4},  {"int64", 8},   {"vec2i", 8},
      {"vec2s", 8},       {"vec2d", 16},     {"vec3u8", 3}, {"vec3u16", 6}, {"vec3i", 12},  {"vec3s", 12},
      {"vec3d", 24},      {"vec4i", 16},     {"vec4s", 16}, {"vec4d", 32},  {"mat3s", 36},  {"mat3d", 72},
      {"mat4s", 64},      {"mat4d", 128},    {"quats", 16}, {"quatd", 32},  {"ptidx32", 4}, {"ptidx64", 8},
      {"ptdataidx32", 4}, {"ptdataidx64", 8}};
  for (const auto& [name, bytes] : sizes)
    if (name == type) return bytes;
  return 0;
}

constexpr std::string_view kHalfFloatSuffix = "_HalfFloat";  // io::HALF_FLOAT_TYPENAME_SUFFIX
constexpr std::string_view kFloatTree = "Tree_float_5_4_3";  // openvdb::FloatTree::treeType()

/// Reads a .vdb file's structure as OpenVDB 10's reader would (file format 222–224:
/// io::Archive::readHeader, MetaMap::readMeta, GridDescriptor::read, and for every float grid
/// Transform::read, Tree::readTopology and Tree::readBuffers with io::readCompressedValues),
/// without allocating anything the file declares. Every declared string length, metadata byte
/// count, grid offset, node count and compressed buffer size is checked against the bytes that
/// are actually there (for a grid: up to its end offset), and the structure OpenVDB trusts
/// (fixed metadata sizes, uncompressed chunk sizes, blosc headers, node order) against what it
/// will read. OpenVDB's reader does not check: a length read past the end of a truncated file is
/// an uninitialised integer, `std::string(size, ' ')` then allocates gigabytes, and
/// io::bloscFromStream allocates whatever compressed size a corrupt leaf declares.
class VdbScanner {
 public:
  VdbScanner(const std::filesystem::path& path, const unsigned char* data, std::uint64_t size)
      : where_(path.string()), data_(data), size_(size), limit_(size) {}

  void check() {
    const auto magic = read<std::int64_t>("magic number");
    if (magic != openvdb::OPENVDB_MAGIC)
      fail("{}: cannot read OpenVDB file: not a .vdb file (bad magic number; looks like {})", where_,
           file_kind(std::string_view(reinterpret_cast<const char*>(data_), std::min<std::uint64_t>(size_, 512))));
    version_ = read<std::uint32_t>("file version");
    if (version_ < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION || version_ > openvdb::OPENVDB_FILE_VERSION) {
      fail("{}: cannot read OpenVDB file: unsupported file format version {} (weft reads {} to {})", where_, version_,
           static_cast<int>(openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION), openvdb::OPENVDB_FILE_VERSION);
    }
    skip(8, "library version");
    const auto has_offsets = read<char>("header");
    if (!has_offsets) fail("{}: cannot read OpenVDB file: no grid offsets (format too old)", where_);
    skip(36, "UUID");
    meta_map("file metadata");
    const auto grids = read<std::int32_t>("grid count");
    if (grids < 0) fail("{}: cannot read OpenVDB file: negative grid count {}", where_, grids);
    for (std::int32_t i = 0; i < grids; ++i) grid(i);
  }

 private:
  std::uint64_t left() const { return limit_ - std::min(limit_, pos_); }

  [[noreturn]] void truncated(const char* what) {
    if (grid_ >= 0 && limit_ < size_) {
      fail("{}: cannot read OpenVDB file: corrupt (grid {}: {} runs past byte {}, where its grid or item ends)", where_,
           grid_, what, limit_);
    }
    fail("{}: cannot read OpenVDB file: truncated ({} bytes; {} cut short)", where_, size_, what);
  }

  template <typename... Args>
  [[noreturn]] void corrupt(fmt::format_string<Args...> format, Args&&... args) {
    fail("{}: cannot read OpenVDB file: corrupt (grid {}: {})", where_, grid_,
         fmt::format(format, std::forward<Args>(args)...));
  }

  /// Bytes [pos, pos + n) of the file, then moves past them.
  const unsigned char* take(std::uint64_t n, const char* what) {
    if (n > left()) truncated(what);
    const unsigned char* p = data_ + pos_;
    pos_ += n;
    return p;
  }

  void skip(std::uint64_t n, const char* what) { (void)take(n, what); }

  template <typename T>
  T read(const char* what) {
    T value{};
    std::memcpy(&value, take(sizeof(T), what), sizeof(T));
    return value;
  }

  /// A length-prefixed string (io::readString): returns it only if short, else skips it.
  std::string string(const char* what) {
    const auto length = read<std::uint32_t>(what);
    const auto* p = take(length, what);
    if (length > 256) return {};
    return std::string(reinterpret_cast<const char*>(p), length);
  }

  /// MetaMap::readMeta: a count, then name, type name and a byte-counted value per item.
  /// Sets `half` from `is_saved_as_half_float` (GridBase::saveFloatAsHalf) when given.
  void meta_map(const char* what, bool* half = nullptr) {
    const auto count = read<std::uint32_t>(what);
    // Each item takes at least 12 bytes (three lengths).
    if (count > left() / 12) truncated(what);
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::string name = string(what);
      const std::string type = string(what);
      const auto bytes = read<std::uint32_t>(what);
      if (bytes > left()) truncated(what);
      const std::uint64_t end = pos_ + bytes;
      if (const auto fixed = fixed_metadata_size(type); fixed != 0 && bytes != fixed) {
        fail("{}: cannot read OpenVDB file: corrupt ({} item '{}' of type {} declares {} bytes, not {})", where_, what,
             name, type, bytes, fixed);
      }
      if (type == "bool" && data_[pos_] > 1) {
        fail("{}: cannot read OpenVDB file: corrupt ({} item '{}' is a bool of value {})", where_, what, name,
             static_cast<int>(data_[pos_]));
      }
      if (name == "is_saved_as_half_float" && half) {
        if (type != "bool")
          fail("{}: cannot read OpenVDB file: corrupt ({} item '{}' is a {}, not a bool)", where_, what, name, type);
        *half = data_[pos_] != 0;
      }
      if (type == "__delayedload" && bytes > 0) delayed_load_meta(what, end);
      pos_ = end;
    }
  }

  /// io::DelayedLoadMetadata::readValue (type "__delayedload"): a count, then per-leaf masks (count bytes) and
  /// compressed sizes (count int64), each raw or as a blosc chunk, within `end`.
  void delayed_load_meta(const char* what, std::uint64_t end) {
    const auto saved = limit_;  // the grid's end (the file's, for file metadata)
    limit_ = end;
    const auto count = read<std::uint32_t>(what);
    // The count is the tree's leaf count, and readValue allocates 9 bytes per leaf (a mask byte and
    // an int64 size) whatever the arrays' chunks hold. Those chunks are no bound: blosc or zip makes a
    // cloth's mostly equal masks and sizes far smaller than one byte a leaf. The tree is: every leaf
    // writes at least its 64-byte value mask in the topology (LeafNode::writeTopology), which comes
    // after this metadata within the grid, so more leaves than those bytes hold cannot be this grid's.
    if (const auto most = (saved - end) / 64; count > most) {
      fail(
          "{}: cannot read OpenVDB file: corrupt ({} declares {} leaves; the {} bytes left in the grid hold at most "
          "{})",
          where_, what, count, saved - end, most);
    }
    const auto array = [&](std::uint64_t bytes, bool optional) {
      const auto declared = read<std::uint32_t>(what);
      if (optional && declared == std::numeric_limits<std::uint32_t>::max()) return;  // not stored
      if (declared == 0) {
        skip(bytes, what);
      } else {
        // compression::bloscCompress pads arrays under 128 bytes to 128 (BLOSC_PAD_BYTES).
        blosc_header(declared, bytes, what, bytes < 128 ? 128 : bytes);
        skip(declared, what);
      }
    };
    array(count, false);
    array(std::uint64_t{count} * 8, true);
    limit_ = saved;
  }

  /// Checks the 16-byte blosc header at the read position: c-blosc trusts the compressed size it
  /// declares (blosc_decompress has no source size), so it must be the chunk's `declared` size,
  /// and it must decompress to the `expected` bytes the reader's buffer holds (or to `padded`
  /// bytes, for which DelayedLoadMetadata sizes its buffer from this header).
  void blosc_header(std::uint64_t declared, std::uint64_t expected, const char* what, std::uint64_t padded = 0) {
    if (declared < 16 || declared > left()) {
      if (declared > left()) truncated(what);
      fail("{}: cannot read OpenVDB file: corrupt ({} declares a {}-byte blosc chunk)", where_, what, declared);
    }
    std::uint32_t nbytes = 0, cbytes = 0;
    std::memcpy(&nbytes, data_ + pos_ + 4, 4);
    std::memcpy(&cbytes, data_ + pos_ + 12, 4);
    if ((nbytes != expected && nbytes != padded) || cbytes != declared) {
      fail(
          "{}: cannot read OpenVDB file: corrupt ({}: a {}-byte blosc chunk declares {} compressed bytes for {} "
          "bytes, expected {})",
          where_, what, declared, cbytes, nbytes, expected);
    }
  }

  /// GridDescriptor::read, then the grid at its offset: compression flags, metadata,
  /// transform, and for a float grid its tree; then on to the next descriptor at the grid's end.
  void grid(std::int32_t index) {
    grid_ = index;
    (void)string("grid name");
    std::string type = string("grid type");
    const bool instance = !string("grid instance parent").empty();
    bool descriptor_half = false;
    if (type.size() > kHalfFloatSuffix.size() && type.ends_with(kHalfFloatSuffix)) {
      type.resize(type.size() - kHalfFloatSuffix.size());
      descriptor_half = true;
    }
    const auto grid_pos = read<std::int64_t>("grid offsets");
    const auto block_pos = read<std::int64_t>("grid offsets");
    const auto end_pos = read<std::int64_t>("grid offsets");
    const auto here = static_cast<std::int64_t>(pos_);
    if (!(here <= grid_pos && grid_pos <= block_pos && block_pos <= end_pos)) {
      fail("{}: cannot read OpenVDB file: corrupt (grid {} has offsets {}, {}, {})", where_, index, grid_pos, block_pos,
           end_pos);
    }
    if (static_cast<std::uint64_t>(end_pos) > size_) {
      fail("{}: cannot read OpenVDB file: truncated ({} bytes; grid {} ends at byte {})", where_, size_, index,
           end_pos);
    }
    pos_ = static_cast<std::uint64_t>(grid_pos);
    limit_ = static_cast<std::uint64_t>(end_pos);
    compression_ = read<std::uint32_t>("grid compression");
    half_ = false;
    meta_map("grid metadata", &half_);
    if (type == kFloatTree && !instance) {
      if (half_ != descriptor_half)
        corrupt("the grid type says {}half float, the metadata says {}", descriptor_half ? "" : "not ",
                half_ ? "half float" : "full float");
      transform(0);
      tree();
    }
    pos_ = static_cast<std::uint64_t>(end_pos);
    limit_ = size_;
    grid_ = -1;
  }

  /// Transform::read: the map's type name, then its fixed-size values (math/Maps.h).
  void transform(int depth) {
    const std::string type = string("grid transform");
    if (type == "AffineMap" || type == "UnitaryMap") {
      skip(128, "grid transform");  // Mat4d
    } else if (type == "ScaleMap" || type == "UniformScaleMap") {
      skip(std::uint64_t{5} * 24, "grid transform");  // five Vec3d
    } else if (type == "TranslationMap") {
      skip(24, "grid transform");
    } else if (type == "ScaleTranslateMap" || type == "UniformScaleTranslateMap") {
      skip(std::uint64_t{6} * 24, "grid transform");
    } else if (type == "NonlinearFrustumMap" && depth == 0) {
      skip(48 + 16, "grid transform");  // bounding box, taper, depth, then a second map
      transform(depth + 1);
    } else {
      corrupt("unknown transform type '{}'", type.substr(0, 64));
    }
  }

  /// Tree::readTopology (buffer count, RootNode: background, tiles, children, each child's
  /// topology depth first), then Tree::readBuffers (each leaf's mask and values, same order).
  void tree() {
    (void)read<std::int32_t>("tree buffer count");
    skip(4, "background value");
    const auto tiles = read<std::uint32_t>("root tile count");
    const auto children = read<std::uint32_t>("root child count");
    if (tiles == 0 && children == 0) return;  // an empty tree has no buffers
    if (tiles > left() / 17) truncated("root tiles");
    for (std::uint32_t i = 0; i < tiles; ++i) {
      (void)root_origin("root tile");
      skip(4, "root tile");  // value
      // The active flag is read straight into a bool: any byte but 0 and 1 is undefined behaviour.
      if (const auto active = read<std::uint8_t>("root tile"); active > 1)
        corrupt("root tile {} has active flag {}", i, static_cast<int>(active));
    }
    // RootNode::readTopology keys its table by the origins read here, and readBuffers then
    // visits the children in key order: the walk below matches it only if they are ascending,
    // as OpenVDB writes them. (A repeated origin also makes OpenVDB leak the first child.)
    leaves_.clear();
    std::int32_t previous[3] = {0, 0, 0};
    for (std::uint32_t i = 0; i < children; ++i) {
      const auto origin = root_origin("root child");
      if (i > 0 && !std::lexicographical_compare(previous, previous + 3, origin.begin(), origin.end()))
        corrupt("root child {} at ({}, {}, {}) is out of order", i, origin[0], origin[1], origin[2]);
      std::copy(origin.begin(), origin.end(), previous);
      internal(5);
    }
    for (std::size_t i = 0; i < leaves_.size(); ++i) {
      const auto active = mask_count(take(64, "leaf value mask"), 64);
      if (active != leaves_[i])
        corrupt("leaf {} has {} active voxels in its topology, {} with its buffer", i, leaves_[i], active);
      values(512, active, "leaf values");
    }
  }

  std::array<std::int32_t, 3> root_origin(const char* what) {
    std::array<std::int32_t, 3> origin{};
    for (auto& c : origin) {
      c = read<std::int32_t>(what);
      if (c % 4096 != 0) corrupt("{} origin {} is not a multiple of 4096", what, c);
    }
    return origin;
  }

  static std::uint32_t mask_count(const unsigned char* mask, std::uint32_t bytes) {
    std::uint32_t on = 0;
    for (std::uint32_t i = 0; i < bytes; i += 8) {
      std::uint64_t word = 0;
      std::memcpy(&word, mask + i, 8);
      on += static_cast<std::uint32_t>(std::popcount(word));
    }
    return on;
  }

  /// InternalNode::readTopology (log2 dim 5 under the root, 4 below): child mask, value mask,
  /// the node's values, then each child's topology in mask order.
  void internal(int log2dim) {
    const std::uint32_t count = 1u << (3 * log2dim);
    const auto* child_mask = take(count / 8, "internal node child mask");
    const auto active = mask_count(take(count / 8, "internal node value mask"), count / 8);
    values(count, active, "internal node values");
    for (std::uint32_t byte = 0; byte < count / 8; ++byte) {
      for (int bit = 0; bit < 8; ++bit) {
        if (!(child_mask[byte] >> bit & 1)) continue;
        if (log2dim == 5) {
          internal(4);
        } else {
          leaves_.push_back(mask_count(take(64, "leaf value mask"), 64));  // LeafNode::readTopology
        }
      }
    }
  }

  /// io::readCompressedValues for a node of `count` values, `active` of them on in its mask.
  void values(std::uint32_t count, std::uint32_t active, const char* what) {
    namespace io = openvdb::io;
    const auto flag = read<std::int8_t>(what);  // which inactive values and masks follow
    if (flag == io::NO_MASK_AND_ONE_INACTIVE_VAL || flag == io::MASK_AND_ONE_INACTIVE_VAL ||
        flag == io::MASK_AND_TWO_INACTIVE_VALS)
      skip(flag == io::MASK_AND_TWO_INACTIVE_VALS ? 8 : 4, what);  // inactive values, full float
    if (flag == io::MASK_AND_NO_INACTIVE_VALS || flag == io::MASK_AND_ONE_INACTIVE_VAL ||
        flag == io::MASK_AND_TWO_INACTIVE_VALS)
      skip(count / 8, what);  // selection mask
    std::uint64_t stored = count;
    if ((compression_ & io::COMPRESS_ACTIVE_MASK) && flag != io::NO_MASK_AND_ALL_VALS) stored = active;
    if (half_ && stored == 0) return;  // HalfReader reads nothing for no values
    const std::uint64_t bytes = stored * (half_ ? 2 : 4);
    if (!(compression_ & (io::COMPRESS_BLOSC | io::COMPRESS_ZIP))) {
      skip(bytes, what);
      return;
    }
    // bloscFromStream / unzipFromStream: an int64 size, negative for raw bytes.
    const auto declared = read<std::int64_t>(what);
    if (declared <= 0) {
      if (declared == std::numeric_limits<std::int64_t>::min() || static_cast<std::uint64_t>(-declared) != bytes)
        corrupt("{} declares a raw chunk of {} bytes, expected {}", what, declared, bytes);
      skip(bytes, what);
      return;
    }
    if (static_cast<std::uint64_t>(declared) > left()) {
      corrupt("{} declares a compressed chunk of {} bytes; {} bytes are left in the grid", what, declared, left());
    }
    if (compression_ & io::COMPRESS_BLOSC) {
      const auto saved = limit_;
      limit_ = pos_ + static_cast<std::uint64_t>(declared);
      blosc_header(static_cast<std::uint64_t>(declared), bytes, what);
      limit_ = saved;
    }
    skip(static_cast<std::uint64_t>(declared), what);
  }

  std::string where_;
  const unsigned char* data_;
  std::uint64_t size_;
  std::uint64_t pos_ = 0;
  std::uint64_t limit_;  // reads stop here: the file's size, or the current grid's end
  std::uint32_t version_ = 0;
  std::int32_t grid_ = -1;
  std::uint32_t compression_ = 0;
  bool half_ = false;
  std::vector<std::uint32_t> leaves_;  // active voxels of each leaf, in topology order
};

// The layout io::File writes (a seekable archive: grid offsets for reading one grid by name), into
// any stream; io::File offers it only onto a file stream of its own.
class SeekableArchive final : public openvdb::io::Archive {
 public:
  void write_to(std::ostream& os, const openvdb::GridCPtrVec& grids) const { write(os, grids, /*seekable=*/true); }
};

}  // namespace

void check_vdb_file(const std::filesystem::path& path) {
  const MappedFile file(path);
  VdbScanner(path, file.data(), file.size()).check();
}

void save_grids(const std::vector<Grid>& grids, const std::filesystem::path& path) {
  ensure_openvdb_initialized();
  for (const auto& g : grids) require_writable(*g.impl().grid, path.string());
  // io::File writes through a stream it never checks, so a full disk would leave a truncated file
  // reported as saved; the archive writes into a stream write_stream_atomically checks instead.
  write_stream_atomically(path, [&](std::ostream& os) {
    try {
      openvdb::GridCPtrVec out;
      for (const auto& g : grids) out.push_back(g.impl().grid);
      const SeekableArchive archive;
      archive.write_to(os, out);
    } catch (const openvdb::Exception& e) {
      fail("{}: cannot write OpenVDB file: {}", path.string(), e.what());
    }
  });
}

std::vector<GridCount> count_grids(const std::filesystem::path& path) {
  ensure_openvdb_initialized();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail("{}: no such file", path.string());
  check_vdb_file(path);  // bounds every length OpenVDB will read
  std::vector<GridCount> out;
  try {
    openvdb::io::File file(path.string());
    file.open(false);
    for (auto it = file.beginName(); it != file.endName(); ++it) {
      if (!file.readGridMetadata(it.gridName())->isType<openvdb::FloatGrid>()) continue;
      const openvdb::GridBase::Ptr g = file.readGrid(it.gridName());
      out.push_back({it.gridName(), g->activeVoxelCount(), static_cast<std::uint64_t>(g->memUsage()),
                     g->saveFloatAsHalf() ? 2 : 4});
    }
    file.close();
  } catch (const openvdb::Exception& e) {
    fail("{}: cannot read OpenVDB file: {}", path.string(), e.what());
  }
  return out;
}

}  // namespace weft::volume
