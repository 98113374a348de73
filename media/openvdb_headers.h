#pragma once
// OpenVDB's headers (openvdb.h brings io/File.h too), with the warnings of our flags silenced
// inside them: include this, not <openvdb/...>, where -Wshadow/-Wconversion/-Wpedantic apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wpedantic"
#include <openvdb/openvdb.h>
#pragma GCC diagnostic pop
