#include "media/vdb_init.h"

#include <mutex>

#include "media/openvdb_headers.h"

namespace femto::vdb_load {

void init_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] {
    openvdb::initialize();
#ifdef FEMTO_SANITIZED_BUILD
    // registerGrid() registers Grid<T>::factory, whose constructor call compiles Grid<T>'s vtable
    // and all its virtual functions into this file. The registry refuses a second factory.
    openvdb::FloatGrid::unregisterGrid();
    openvdb::FloatGrid::registerGrid();
#endif
  });
}

}  // namespace femto::vdb_load
