#pragma once
// The process's memory as the operating system sees it, and giving freed heap back to it.
//
// Why: every session's render thread, scene-load thread and GL driver threads allocate from their
// own allocator arenas; when a session ends its memory is freed, but glibc keeps free pages inside
// each arena's heap until something asks for them. Over many sessions the resident size then
// settles at a level that depends on which threads happened to share an arena (measured: 199 MiB
// after trimming against 270-325 MiB untrimmed for the same 50 sessions), so an operator cannot tell
// a leak from the allocator's hoard.
#include <cstddef>
#include <optional>

namespace gis {

/// The resident set size in bytes (Linux: /proc/self/statm), or nothing where it cannot be read.
std::optional<std::size_t> residentBytes();

/// Hands free heap pages in every allocator arena back to the system (glibc's malloc_trim; a no-op
/// elsewhere). Costs a few milliseconds (2-7 ms measured after a session teardown), and the next
/// allocations fault their pages in again: call it after memory-heavy work ends, not per frame.
void releaseFreedMemory();

} // namespace gis
