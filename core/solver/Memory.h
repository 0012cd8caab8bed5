#pragma once
// How the process's allocator treats large blocks.

namespace tp {

/// Keeps freed memory in the process for the next allocation instead of handing it back to the
/// kernel (glibc's mallopt: blocks up to 1 GB come from the heap rather than from a mapping of
/// their own, and the heap's free top is returned only beyond 1 GB; a thread's own arena still
/// maps blocks larger than its 64 MB heaps). Every new site, level and factorisation allocates the
/// tangent, the factor and CHOLMOD's workspace afresh, tens of MB each; with glibc's defaults each
/// of those is a fresh mapping whose every 4 kB page faults on first touch, and page faults are
/// costly in a virtual machine (19 µs each on the 2-core VM of bench/README.md: a 64 MB block took
/// 0.15 s to fault in). The process keeps its peak memory (+4 % peak RSS on the CLI's default
/// indentation). Idempotent; a no-op off glibc. Called by the front ends' main() and by every
/// CholmodSolver's constructor (so tests and benchmarks get it too).
void keepFreedMemory();

}  // namespace tp
