// The process's heap kept between captures. A line runs one runtime capture
// after capture; each Process() allocates and frees the same ~1-2 MB maps
// (a 752x582 float image is 1.75 MB). glibc's defaults hand such blocks
// back to the kernel on free (their own mappings, or the heap's top trimmed
// beyond 2x the largest freed), so every capture faults them in again, a
// zeroed 4 KB page at a time: the bench counted ~6 200 faults per object,
// and on this VM each costs ~15 us (the host maps the page too), ~1/4 of
// the runtime's CPU time. Kept: blocks below 8 MB come from the heap, and
// up to 32 MB free at each heap's top stays mapped. Measured with
// `stereorig bench` (docs/reconstruct-log.md, "Memory kept between captures"):
// ~70 faults per object, +45 % objects/s, and the runtime's own peak
// +20-35 MB (the free memory each thread's heap keeps).
//
// Process-wide (malloc's settings); the CLI applies it at start-up. A host
// program embedding the runtime calls it itself, or tunes its allocator.
#pragma once

#include <cstddef>

namespace stereorig {

constexpr size_t kHeapMmapThresholdBytes = size_t(8) << 20;
constexpr size_t kHeapTrimThresholdBytes = size_t(32) << 20;

// Sets malloc's mmap and trim thresholds to the above. Returns false where
// that is not possible (not glibc); the runtime works the same, slower.
bool RetainFreedHeapMemory();

}  // namespace stereorig
