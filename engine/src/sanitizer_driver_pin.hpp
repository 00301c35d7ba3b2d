// See sanitizer_driver_pin.cpp: in ASan builds, pins the process's loaded GL driver so
// LeakSanitizer keeps scanning its globals after Mesa dlcloses it. No-op otherwise.
#pragma once

namespace dyncull::detail {

/// Call with a context current (the driver is loaded by then). Idempotent.
void pinLoadedGlDrivers();

}  // namespace dyncull::detail
