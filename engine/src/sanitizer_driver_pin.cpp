// Sanitizer builds only: keeps the loaded Mesa DRI driver mapped for the life of the
// process. Mesa dlcloses its driver on eglTerminate/context teardown; LeakSanitizer then
// no longer scans the driver's globals and reports the driver's still-referenced heap
// blocks as leaks from an "<unknown module>" (unsuppressible, and not real leaks). Pinning
// the driver (RTLD_NODELETE) keeps those globals scanned, so the sanitizer run needs no
// leak suppressions at all. Normal builds compile this to nothing.
#include "sanitizer_driver_pin.hpp"

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>

#include <cstring>
#include <string>
#include <vector>
#endif

namespace dyncull::detail {

#if defined(__SANITIZE_ADDRESS__)
void pinLoadedGlDrivers() {
    std::vector<std::string> drivers;
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void* out) {
            const char* name = info->dlpi_name;
            if (name && (std::strstr(name, "_dri.so") || std::strstr(name, "libgallium")))
                static_cast<std::vector<std::string>*>(out)->emplace_back(name);
            return 0;
        },
        &drivers);
    // RTLD_NOLOAD: only upgrades an already-loaded module to no-delete; the handle is
    // deliberately never closed.
    for (const std::string& d : drivers) dlopen(d.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
}
#else
void pinLoadedGlDrivers() {}
#endif

}  // namespace dyncull::detail
