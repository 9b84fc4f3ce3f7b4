#pragma once
// Keeps the GL driver that EGL loaded resident for the life of the process.
//
// Mesa loads its driver (e.g. swrast_dri.so, libgallium) on eglInitialize and unloads it
// on the last eglTerminate. The driver holds process-wide allocations in its globals;
// once unloaded, LeakSanitizer can no longer see the pointers to them and reports a leak
// at exit, and every new output pays for loading the driver again. Pinning the driver
// (RTLD_NODELETE on the already loaded object) avoids both.
namespace procam::output::egl {

// Pins every loaded object whose file name looks like a Mesa driver; returns how many
// it pinned. Cheap after the first call (objects already pinned are skipped).
int pinLoadedGlDrivers();

}  // namespace procam::output::egl
