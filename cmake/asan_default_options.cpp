// Linked into physval and every test executable of a PHYSVAL_SANITIZE build (top-level
// CMakeLists.txt): AddressSanitizer's defaults for them, read before main and before any
// static constructor; ASAN_OPTIONS still overrides each one.
//
// intercept_tls_get_addr=0: LeakSanitizer must not track dynamic TLS through its
// __tls_get_addr hook. GCC 12's runtime guesses the size of a dynamic TLS block (the ODE
// plugin's thread_locals, libphysval_ode.so) from a "glibc 2.19 header" whenever the
// block's address is 16 mod 4096; glibc 2.36 mallocs the block, so about one address in
// 128 (ASan's 32-byte chunks) reads ASan's own chunk header as {start, size}: LSan then
// scans [0xbe9, 0x1000001ceb) at exit and its tracer dies ("Tracer caught signal 11",
// google/sanitizers#1322). Which address the block gets depends on every allocation
// before it, so any change anywhere could turn a test red (cde3fb9 did). The blocks stay
// reachable without the hook: glibc's dtv, which LSan scans with the static TLS, points
// to them.
extern "C" __attribute__((visibility("default"), used)) const char* __asan_default_options() {
  return "intercept_tls_get_addr=0";
}
