#pragma once
// The tilt drivers behind the plugin ABI (plugins/include/procamd/procam_plugin.h):
// iio, i2c, hid and gpio, one factory each, in one plugin table. The table is linked
// statically into procamd (procam_tilt_plugin_entry) and also built as the loadable
// procam-tilt.so. Options are documented in drivers/tilt/README.md.
//
// The create*On() functions are the drivers' create() after the transport is open;
// tests pass simulated transports (register maps, stored HID reports, scripted lines).
#include <procamd/procam_plugin.h>

#include <memory>

#include "tilt/gpio/ball_switch.hpp"
#include "tilt/hid/hid_accelerometer.hpp"
#include "tilt/i2c/i2c_bus.hpp"

namespace procam::tilt::plugin {

extern const procam_driver_factory kIioFactory;
extern const procam_driver_factory kI2cFactory;
extern const procam_driver_factory kHidFactory;
#if PROCAM_TILT_GPIOD
extern const procam_driver_factory kGpioFactory;
#endif

int createI2cOn(std::shared_ptr<I2cBus> bus, const procam_device_desc* desc,
                const procam_config* config, procam_device* out, char* err, std::size_t len);
int createHidOn(std::unique_ptr<HidTransport> transport, const procam_config* config,
                procam_device* out, char* err, std::size_t len);
int createGpioOn(std::unique_ptr<GpioLines> lines, const procam_config* config, procam_device* out,
                 char* err, std::size_t len);

}  // namespace procam::tilt::plugin

extern "C" const procam_plugin_table* procam_tilt_plugin_entry(void);
