#pragma once
// OpenVDB's set-up, once per process, and which compiled copy of its grid code reads femto's
// .vdb files (docs/RELIABILITY.md, "Sanitizers").

namespace femto::vdb_load {

/// openvdb::initialize(), once per process (reading and writing need it). In sanitizer builds it
/// then gives OpenVDB's grid registry factories compiled in femto for the grid types femto reads
/// (float media, int32 labels): grids read from files are made by the registry, so they run this
/// build's instrumented copy of the grid code (readTopology, readBuffers...), and the sanitizers
/// check OpenVDB's reader and the fuzzer sees its coverage. Other builds use OpenVDB's library's
/// copy, the same code.
void init_openvdb();

}  // namespace femto::vdb_load
