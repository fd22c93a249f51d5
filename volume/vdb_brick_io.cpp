#include "volume/vdb_brick_io.h"

#include <openvdb/io/File.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <tuple>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "volume/detail/vdb_grid.h"

namespace raysift::volume {

namespace {

/// rchar of /proc/self/io: bytes this process read through read() and friends (0 where it is unavailable).
std::uint64_t process_bytes_read() {
  std::ifstream io("/proc/self/io");
  std::string key;
  std::uint64_t value = 0;
  while (io >> key >> value)
    if (key == "rchar:") return value;
  return 0;
}

/// OpenVDB's message, one line and short: on a truncated file it can quote kilobytes of garbage as a name.
std::string short_reason(const std::string& what) {
  std::string out;
  for (char c : what) {
    const bool printable = c >= 0x21 && c <= 0x7e;
    if (printable) out += c;
    else if (!out.empty() && out.back() != ' ') out += ' ';
    if (out.size() >= 120) return out + "...";
  }
  return out;
}

/// Bounds-checked reads of the archive's framing (the format of openvdb/io/Archive.cc and GridDescriptor.cc).
struct FrameReader {
  std::ifstream in;
  std::uint64_t size;
  template <typename T>
  T value() {
    T v{};
    in.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!in) throw IoError("ends inside its header");
    return v;
  }
  void skip(std::uint64_t bytes) {
    const auto at = std::uint64_t(in.tellg());
    if (bytes > size - at) throw IoError("ends inside its header");
    in.seekg(std::streamoff(bytes), std::ios::cur);
  }
  void skip_string() { skip(value<std::uint32_t>()); }
};

/// Throws IoError unless the header, metadata and grid descriptors parse within the file and every grid ends
/// inside it. io::File reads with unchecked streams: on a truncated file it would read garbage sizes and
/// allocate gigabytes (delayed loading) instead of failing.
void check_archive_intact(const std::string& path) {
  FrameReader r{std::ifstream(path, std::ios::binary), std::uint64_t(std::filesystem::file_size(path))};
  auto fail = [&](const std::string& why) {
    return IoError(file_message(path, "not a valid OpenVDB file or truncated/corrupt (" + why +
                                          "); re-export it or check the download"));
  };
  try {
    if (r.value<std::int64_t>() != 0x56444220) throw IoError("no VDB magic number");
    const auto version = r.value<std::uint32_t>();
    if (version >= 211) r.skip(8);  // library major and minor version
    const bool offsets = version >= 212 && r.value<char>() != 0;
    if (version >= 220) r.skip(36);  // UUID
    for (auto meta = r.value<std::uint32_t>(); meta > 0; --meta) {  // file metadata: name, type, sized value
      r.skip_string();
      r.skip_string();
      r.skip(r.value<std::uint32_t>());
    }
    if (!offsets) return;  // pre-2.0 files: nothing to check cheaply
    for (auto grids = r.value<std::int32_t>(); grids > 0; --grids) {
      r.skip_string();                     // unique name
      r.skip_string();                     // grid type
      if (version >= 216) r.skip_string();  // instance parent
      const auto grid_pos = r.value<std::int64_t>(), block_pos = r.value<std::int64_t>();
      const auto end_pos = r.value<std::int64_t>();
      if (!(grid_pos <= block_pos && block_pos <= end_pos && std::uint64_t(end_pos) <= r.size))
        throw IoError("a grid ends at byte " + std::to_string(end_pos) + " of " + std::to_string(r.size));
      r.in.seekg(end_pos);
    }
  } catch (const IoError& e) {
    throw fail(e.what());
  }
}

/// Runs `read` with OpenVDB's and the C++ library's failures turned into one IoError naming the file.
template <typename F>
auto guarded_read(const std::string& path, F&& read) {
  require_readable_file(path);  // IoError for missing / directory / unreadable, as load_vdb
  check_archive_intact(path);
  detail::ensure_openvdb_initialized();
  try {
    return read();
  } catch (const openvdb::Exception& e) {
    throw IoError(file_message(path, "not a valid OpenVDB file or truncated/corrupt (" + short_reason(e.what()) +
                                         "); re-export it or check the download"));
  } catch (const std::ios_base::failure& e) {
    throw IoError(file_message(path, "truncated or unreadable (" + short_reason(e.what()) + ")"));
  } catch (const std::bad_alloc&) {
    throw IoError(file_message(path, "not a valid OpenVDB file (a size field is implausibly large)"));
  }
}

openvdb::GridBase::Ptr find_grid(const std::string& path, const openvdb::GridPtrVec& grids, const std::string& name) {
  std::vector<GridInfo> kinds;
  for (const auto& g : grids) {
    GridInfo k;
    k.name = g->getName();
    k.type = g->isType<openvdb::FloatGrid>() ? "float" : g->valueType();
    k.active_voxels = g->activeVoxelCount();  // node masks only: no delay-loaded buffer is touched
    kinds.push_back(k);
  }
  const std::string chosen = name.empty() ? default_grid_name(kinds) : name;
  for (std::size_t i = 0; i < grids.size(); ++i) {
    if (kinds[i].name != chosen) continue;
    if (kinds[i].type != "float")
      throw InvalidInput(file_message(path, "grid '" + chosen + "' has value type '" + kinds[i].type +
                                                "', expected a float grid"));
    return grids[i];
  }
  throw InvalidInput(file_message(path, chosen.empty() ? "no float grid to load (raysift renders scalar float grids only)"
                                                       : "no grid named '" + chosen + "'"));
}

void add_active_tile(const openvdb::CoordBBox& box, std::vector<LeafCount>& out) {
  for (int z = box.min().z(); z <= box.max().z(); z += 8)
    for (int y = box.min().y(); y <= box.max().y(); y += 8)
      for (int x = box.min().x(); x <= box.max().x(); x += 8) out.push_back({{x, y, z}, 512});
}

/// Applies NonFinite::Error (throw) or Background (switch off) to the active values; returns how many changed.
std::uint64_t drop_non_finite(const std::string& path, openvdb::FloatGrid& grid, NonFinite policy) {
  if (policy == NonFinite::Clamp)
    throw InvalidInput("--non-finite clamp needs the whole grid's value range; a brick read supports error and "
                       "background");
  std::uint64_t bad = 0;
  for (auto v = grid.tree().beginValueOn(); v; ++v) {
    if (std::isfinite(*v)) continue;
    bad += v.getVoxelCount();
    if (policy == NonFinite::Background) {
      v.setValue(grid.background());
      v.setValueOff();
    }
  }
  if (bad > 0 && policy == NonFinite::Error)
    throw InvalidInput(file_message(path, "grid '" + grid.getName() + "' has " + std::to_string(bad) +
                                              " NaN/Inf voxel values in this brick (non-finite policy 'error'; "
                                              "'background' loads it)"));
  return bad;
}

}  // namespace

VdbLayout read_vdb_layout(const std::string& path, const std::string& grid_name) {
  return guarded_read(path, [&] {
    openvdb::io::File file(path);
    file.open(/*delayLoad=*/true);
    const openvdb::GridPtrVecPtr grids = file.getGrids();
    const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(find_grid(path, *grids, grid_name));
    VdbLayout layout;
    layout.grid = grid->getName();
    const openvdb::FloatTree& tree = grid->tree();
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
      const openvdb::Coord o = leaf->origin();
      if (const auto n = leaf->onVoxelCount(); n > 0) layout.leaves.push_back({{o.x(), o.y(), o.z()}, std::uint32_t(n)});
    }
    auto tile = tree.cbeginValueOn();
    tile.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tile; ++tile) add_active_tile(tile.getBoundingBox(), layout.leaves);
    std::sort(layout.leaves.begin(), layout.leaves.end(), [](const LeafCount& a, const LeafCount& b) {
      return std::tie(a.origin.z, a.origin.y, a.origin.x) < std::tie(b.origin.z, b.origin.y, b.origin.x);
    });
    layout.active_voxels = tree.activeVoxelCount();
    if (layout.active_voxels > 0) {
      const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
      layout.index_min = {box.min().x(), box.min().y(), box.min().z()};
      layout.index_max = {box.max().x(), box.max().y(), box.max().z()};
    }
    file.close();
    return layout;
  });
}

BrickLoad load_vdb_brick(const std::string& path, const std::string& grid_name, const Vec3i& lo, const Vec3i& hi,
                         const LoadVdbOptions& options) {
  BrickLoad out;
  const std::uint64_t read_before = process_bytes_read();
  auto grid = guarded_read(path, [&] {
    openvdb::io::File file(path);
    file.open(/*delayLoad=*/false);
    const openvdb::GridBase::Ptr meta = file.readGridMetadata(grid_name);  // metadata and transform only
    openvdb::BBoxd world;  // the index box's world bounds (any linear transform), one voxel wider for rounding
    for (int c = 0; c < 8; ++c) {
      const openvdb::Vec3d p((c & 1) ? hi.x + 1 : lo.x - 1, (c & 2) ? hi.y + 1 : lo.y - 1, (c & 4) ? hi.z + 1 : lo.z - 1);
      world.expand(meta->indexToWorld(p));
    }
    auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(grid_name, world));
    if (!g) throw InvalidInput(file_message(path, "grid '" + grid_name + "' is not a float grid"));
    file.close();
    return g;
  });
  out.bytes_read = process_bytes_read() - read_before;
  if (!std::isfinite(grid->background()))
    throw InvalidInput(file_message(path, "grid '" + grid_name + "' has a NaN/Inf background value"));
  grid->clip(openvdb::CoordBBox(openvdb::Coord(lo.x, lo.y, lo.z), openvdb::Coord(hi.x, hi.y, hi.z)));
  out.non_finite = drop_non_finite(path, *grid, options.non_finite);
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = grid;
  out.volume = Volume(impl);
  return out;
}

}  // namespace raysift::volume
