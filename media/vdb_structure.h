#pragma once
// A structural check of a .vdb file done with our own bounded reads before OpenVDB sees it:
// OpenVDB trusts the lengths and offsets stored in the file, so a corrupt byte there can make it
// allocate gigabytes or read far past the end (docs/RELIABILITY.md).
#include <string>

namespace femto {

/// Empty when the header, the file metadata, every grid descriptor, every grid's metadata and
/// transform, and the start of every float grid's tree are well formed: known magic and version,
/// every string, metadata value and grid offset inside the file, fixed-size metadata values of
/// their type's size, known transform types, and a root node whose tiles and children fit the
/// bytes before the grid's data. Otherwise a one-line problem, e.g. "grid 1: metadata 'class'
/// claims 1e9 bytes but the file has 312 left". The nodes below the root are not checked.
std::string vdb_structure_problem(const std::string& path);

}  // namespace femto
