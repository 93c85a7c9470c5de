/* The runtime's implementation, compiled as C99 (-pedantic): a C engine can drop the header in.
 * The C++ tests link against these definitions. */
#define ANIMORDER_RUNTIME_IMPLEMENTATION
#include "animorder_runtime.h"

int animorder_runtime_c_check(void) {
    animorder_runtime rt;
    return animorder_runtime_open(&rt, "", 0) == -2 ? 0 : 1;
}
