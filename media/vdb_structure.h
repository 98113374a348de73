#pragma once
// A structural check of a .vdb file done with our own bounded reads before OpenVDB sees it:
// OpenVDB trusts the lengths and offsets stored in the file, so a corrupt byte there can make it
// allocate gigabytes or read far past the end (docs/RELIABILITY.md).
#include <string>

namespace femto {

/// Empty when the header, the file metadata, every grid descriptor, every grid's metadata and
/// transform, and every float grid's tree are well formed: known magic and version, every
/// string, metadata value and grid offset inside the file, fixed-size metadata values of their
/// type's size, known transform types, a root node whose tiles and children fit the bytes before
/// the grid's data, and every node's masks and value chunks (raw, zip or blosc) of the size the
/// node gives them. Otherwise a one-line problem, e.g. "grid 1 metadata entry 2 claims 1000000000
/// bytes at offset 312 but only 80 remain". Compressed chunks are not decompressed here.
std::string vdb_structure_problem(const std::string& path);

}  // namespace femto
