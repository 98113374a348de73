#pragma once
// OpenVDB's set-up, once per process, and which compiled copy of its grid code reads femto's
// .vdb files (docs/RELIABILITY.md, "Sanitizers").

namespace femto::vdb_load {

/// openvdb::initialize(), once per process (reading and writing need it). In sanitizer builds it
/// then gives OpenVDB's grid registry a float-grid factory compiled in femto: float grids read
/// from files (media, the fuzzer's target) are made by the registry, so they run this build's
/// instrumented copy of the grid code (readTopology, readBuffers...), and the sanitizers check
/// OpenVDB's reader and the fuzzer sees its coverage. Other builds, and other grid types (int32
/// labels: 40 s more of the sanitizer build's compile), use OpenVDB's library's copy of the same
/// code.
void init_openvdb();

}  // namespace femto::vdb_load
