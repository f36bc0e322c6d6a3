// The fuzz build compiles tinyobjloader from its header, so its parser gets the fuzzer's
// coverage instrumentation and the sanitizers (Debian's shared library has neither). The
// executable's definitions take precedence over the library's.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
