#pragma once
/// \file Memory checks made before a stage allocates: a command estimates its big buffers, compares them with
/// the limit (--max-memory, default the kernel's MemAvailable) and fails with a one-line message naming the
/// bytes, instead of meeting the OOM killer halfway through. Estimates count the buffers a stage allocates in
/// proportion to its input (pixels, voxels), not small fixed overheads.
#include <cstdint>
#include <string>

namespace raysift {

/// Bytes a new allocation may use: MemAvailable from /proc/meminfo, or UINT64_MAX where it cannot be read.
std::uint64_t available_memory_bytes();

/// "24G", "512M", "1.5G", "4096" (bytes; K/M/G/T are powers of 1024, a trailing B or iB is allowed).
/// \throw InvalidInput naming `text` for anything else, zero, or a size beyond 2^64.
std::uint64_t parse_byte_size(const std::string& text);

/// "1.50 GiB (1610612736 bytes)": KiB up to EiB, so that small limits still read as numbers.
std::string format_bytes(std::uint64_t bytes);

/// a*b*..., or UINT64_MAX on overflow (a voxel count whose byte size does not fit 64 bits needs no other test).
std::uint64_t saturating_product(std::uint64_t a, std::uint64_t b);

/// Who chose the size: a flag value (UsageError, exit 2) or an input file (ResourceError, exit 1).
enum class SizeSource { Flag, Input };

/// The limit in force and where it came from, for the message.
struct MemoryLimit {
  std::uint64_t bytes = 0;        ///< 0 = available_memory_bytes()
  bool from_flag = false;         ///< set with --max-memory
};

/// \throw UsageError (SizeSource::Flag) or ResourceError (Input): "<what> needs <bytes>, more than the
///        <limit> (MemAvailable | --max-memory) allows; <hint>" when `needed_bytes` exceeds the limit.
void require_memory(std::uint64_t needed_bytes, const MemoryLimit& limit, SizeSource source, const std::string& what,
                    const std::string& hint = "");

}  // namespace raysift
