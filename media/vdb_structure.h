#pragma once
// A structural check of a .vdb file done with our own bounded reads before OpenVDB sees it:
// OpenVDB trusts the lengths and offsets stored in the file, so a corrupt byte there can make it
// allocate gigabytes or read far past the end (docs/RELIABILITY.md).
#include <string>

namespace femto {

/// Empty when the header, the file metadata, every grid descriptor and every grid's metadata are
/// well formed: known magic and version, and every string, metadata value and grid offset inside
/// the file. Otherwise a one-line problem, e.g. "grid 1: metadata 'class' claims 1e9 bytes but
/// the file has 312 left". The grid trees themselves are not checked.
std::string vdb_structure_problem(const std::string& path);

}  // namespace femto
