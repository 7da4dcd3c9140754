// LeakSanitizer's default suppressions for an instrumented rbdem binary (tests/sanitize.sh builds one): the leaks
// inside gmsh and OpenCASCADE, whose globals gmsh::finalize() does not free, so that the binary run by hand or by
// another tool (without LSAN_OPTIONS) reports only leaks of rbdem's own allocations. The list is tests/lsan.supp,
// read at configure time (apps/CMakeLists.txt), the one list the test executables use through LSAN_OPTIONS.
#include "lsan_suppressions.hpp"

#if defined(__SANITIZE_ADDRESS__)
extern "C" const char* __lsan_default_suppressions() { return rbdem_lsan_suppressions; }
#endif
