#pragma once
/// \file How the process keeps freed memory. A frame allocates several frame-sized buffers (a 1440x900 RGBA float
/// image is 20 MB). glibc serves such blocks with mmap and unmaps them when freed, so every frame faults its pages
/// in again: measured on the 2-core CI machine, a fresh 20 MB buffer costs 54 ms (about 10 us per 4 KB page
/// fault), a reused one 1 ms, against a 50-100 ms frame at 10% of the full render. Entry points (the raysift
/// program, the Python module, the benches) call keep_freed_buffers_for_reuse() once at start-up.

namespace raysift {

/// Serve blocks up to glibc's largest mmap threshold (32 MiB: frames up to 1920x1080 RGBA float) from the heap
/// and never trim the heap, so a freed frame buffer is reused by the next frame instead of being unmapped.
/// Larger blocks keep glibc's behaviour. A no-op where the C library is not glibc. \return true if applied.
bool keep_freed_buffers_for_reuse();

}  // namespace raysift
