#pragma once
/// \file Import of dense scalar volumes (headerless raw, optionally gzip-compressed, and NRRD) into a sparse
/// `Volume`: voxels within `tolerance` of the background stay inactive, so air around a CT scan costs nothing.
/// Raw files are x fastest, then y, then z. Voxel (0,0,0) sits at the world origin (or the NRRD `space origin`)
/// and world = origin + index * spacing (NRRD: origin + the space directions applied to the index).
#include <cstdint>
#include <optional>
#include <string>

#include "core/memory_limit.h"
#include "core/vec.h"
#include "volume/volume.h"

namespace raysift::volume {

enum class ScalarType { U8, I8, U16, I16, U32, I32, F32, F64 };
enum class Endian { Little, Big };

/// "u8", "i16", "f32", ... \throw InvalidInput for an unknown name (the message lists the valid ones).
ScalarType scalar_type_from_name(const std::string& name);
std::string scalar_type_name(ScalarType type);
int scalar_type_bytes(ScalarType type);

/// What a headerless raw file cannot tell.
struct RawLayout {
  Vec3i dims;                       ///< voxels along x, y, z; each > 0
  ScalarType type = ScalarType::U8;
  Endian endian = Endian::Little;   ///< ignored for 1-byte types
};

struct ImportOptions {
  std::optional<Vec3d> spacing;     ///< world units per voxel; default 1,1,1 for raw, the header's for NRRD
  std::string grid_name = "density";
  float background = 0.0f;          ///< value of inactive voxels, in the file's value units
  float tolerance = 0.0f;           ///< |v - background| <= tolerance stays inactive (>= 0)
  /// If set, the dense data plus the grid it may become (every voxel active) are checked against it before
  /// the data is read or decompressed: ResourceError naming the bytes. Null = no check.
  const MemoryLimit* memory_limit = nullptr;
};

/// Reads a raw file; a name ending in `.gz` is gunzipped first.
/// \throw IoError file missing, a directory, unreadable, or corrupt gzip data.
/// \throw InvalidInput non-positive dims, a dims product overflowing 64 bits, a size mismatch (the message gives
///        expected and actual bytes), a NaN/Inf float voxel, or bad options (spacing <= 0, tolerance < 0).
/// \throw ResourceError see ImportOptions::memory_limit.
Volume import_raw(const std::string& path, const RawLayout& layout, const ImportOptions& options = {});

/// Reads a NRRD file (`.nrrd` with attached data or `.nhdr` with a detached `data file`). Supported: 3 dimensions,
/// types int8..uint32/float/double, encodings raw, gzip and ascii, `endian`, `byte skip`, `line skip`,
/// `spacings` or `space directions`, `space origin`. Space directions (rotation, shear, flips) and the origin
/// become the grid's affine transform: world = origin + i*d0 + j*d1 + k*d2, in the NRRD's own space
/// coordinates (`space` RAS/LPS is not converted). ImportOptions::spacing replaces the directions' lengths.
/// \throw IoError as import_raw, also for a missing detached data file.
/// \throw InvalidInput a malformed or unsupported header ("file:LINE: problem"), plus the import_raw cases.
Volume import_nrrd(const std::string& path, const ImportOptions& options = {});

/// True if the file name ends in .nrrd or .nhdr (case-insensitive).
bool is_nrrd_path(const std::string& path);

}  // namespace raysift::volume
