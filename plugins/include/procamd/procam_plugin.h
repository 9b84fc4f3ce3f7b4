/* procamd driver plugin ABI.
 *
 * A plugin is a shared object (or, for in-tree drivers, a statically linked
 * library) that exports two symbols:
 *
 *   const uint32_t procam_plugin_abi_version;          (data, read first)
 *   const procam_plugin_table* procam_plugin_entry(void);
 *
 * The loader reads procam_plugin_abi_version before calling anything in the
 * plugin and refuses the plugin when it differs from PROCAM_PLUGIN_ABI_VERSION.
 * PROCAM_PLUGIN_DEFINE(entry_function) defines both symbols.
 *
 * Rules across this boundary: plain C types only; no exceptions may leave a
 * plugin function (C++ plugins catch everything); functions that can fail
 * return PROCAM_OK or a negative PROCAM_E* code and write a NUL-terminated
 * reason into the caller's buffer. Every string and table returned by a plugin
 * stays valid until the plugin is unloaded. Units: metres, seconds (as
 * nanoseconds where integral), radians, m/s^2; image coordinates and frames
 * follow the project's conventions (x right, y down, z forward).
 */
#ifndef PROCAMD_PROCAM_PLUGIN_H
#define PROCAMD_PROCAM_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Bumped on every incompatible change of the types shared by every family
 * (descriptions, images, the device and factory structs, the plugin table).
 * Each family's operations table carries its own `version` as its first
 * member: a new operation appended to one table bumps only that family's
 * version, and the daemon reads an operation only from a table whose version
 * has it (PipeWire's SPA interfaces follow the same rule). */
#define PROCAM_PLUGIN_ABI_VERSION 2u

/* The operations table versions this header describes. */
#define PROCAM_CAMERA_OPS_VERSION 2u
#define PROCAM_TILT_OPS_VERSION 3u
#define PROCAM_TRACKER_OPS_VERSION 1u
#define PROCAM_OUTPUT_OPS_VERSION 4u

#define PROCAM_PLUGIN_ABI_SYMBOL "procam_plugin_abi_version"
#define PROCAM_PLUGIN_ENTRY_SYMBOL "procam_plugin_entry"

/* Status codes. */
#define PROCAM_OK 0
#define PROCAM_EINVAL (-1) /* bad argument or configuration */
#define PROCAM_ENODEV (-2) /* device gone or not present */
#define PROCAM_EIO (-3)    /* device reported an error */
#define PROCAM_ETIMEDOUT (-4)
#define PROCAM_EAGAIN (-5)  /* no data yet; poll the device fd */
#define PROCAM_ENOTSUP (-6) /* operation not supported by this driver */
#define PROCAM_EINTERNAL (-7)
#define PROCAM_EEND (-8)      /* the stream ended for good (a finished recording) */
#define PROCAM_ECANCELED (-9) /* the caller asked the operation to stop */

typedef enum procam_family {
  PROCAM_FAMILY_CAMERA = 1,
  PROCAM_FAMILY_TILT = 2,
  PROCAM_FAMILY_TRACKER = 3,
  PROCAM_FAMILY_OUTPUT = 4
} procam_family;

/* One key/value pair. */
typedef struct procam_kv {
  const char* key;
  const char* value;
} procam_kv;

/* A device as the daemon found it (udev, configuration or the virtual rig).
 * Any pointer may be NULL when unknown. */
typedef struct procam_device_desc {
  procam_family family;
  const char* subsystem;       /* "video4linux", "iio", "hidraw", "i2c-dev", "gpio", "drm", "sim" */
  const char* devnode;         /* "/dev/video0" */
  const char* syspath;         /* "/sys/devices/..." */
  const char* name;            /* human readable, or the configured name */
  const procam_kv* properties; /* udev properties (PROCAM_ROLE, ID_VENDOR_ID, ...) */
  size_t n_properties;
} procam_device_desc;

/* Driver options from the daemon's configuration, as text. */
typedef struct procam_config {
  const procam_kv* options;
  size_t n_options;
} procam_config;

/* An 8- or 16-bit image, rows top to bottom, `stride` bytes per row. */
typedef enum procam_pixel_format {
  PROCAM_PIXEL_GRAY8 = 1,
  PROCAM_PIXEL_GRAY16 = 2,
  PROCAM_PIXEL_RGB8 = 3,
  PROCAM_PIXEL_RGBA8 = 4 /* R G B A bytes; outputs take it without conversion */
} procam_pixel_format;

typedef struct procam_image {
  uint32_t width;
  uint32_t height;
  uint32_t stride;
  procam_pixel_format format;
  uint8_t* data;
  uint64_t timestamp_ns; /* CLOCK_MONOTONIC */
} procam_image;

/* What a camera runs at now (procam_camera_ops::get_settings). NaN where the
 * driver cannot tell. */
typedef struct procam_camera_settings {
  double exposure_s; /* exposure time, seconds */
  double gain;       /* in the unit of the driver's `gain` option */
  uint32_t gain_db;  /* 1 when `gain` is in dB, 0 for a device unit */
} procam_camera_settings;

/* Camera. `capture` fills `out` with a buffer owned by the driver that stays
 * valid until the next capture or destroy. */
typedef struct procam_camera_ops {
  uint32_t version; /* PROCAM_CAMERA_OPS_VERSION the driver was built with */
  int (*get_format)(void* self, uint32_t* out_width, uint32_t* out_height,
                    procam_pixel_format* out_format);
  int (*set_exposure)(void* self, double seconds, char* err, size_t err_len);
  int (*capture)(void* self, int timeout_ms, procam_image* out, char* err, size_t err_len);
  /* Optional (may be NULL): a cheap liveness check, PROCAM_OK while the camera
   * answers and PROCAM_ENODEV once it is gone. The daemon checks every camera
   * that delivered no frame for a second; without `check` it captures a frame,
   * which a camera that renders or transfers large frames pays for. */
  int (*check)(void* self, char* err, size_t err_len);
  /* Version 2, optional (may be NULL): the exposure and gain the camera runs at,
   * read from the device where it can tell (an installer aiming a camera wants
   * the values in effect, automatic exposure included). */
  int (*get_settings)(void* self, procam_camera_settings* out);
} procam_camera_ops;

/* Tilt sensor: specific force in the sensor frame (m/s^2). At rest it reads
 * the opposite of gravity, i.e. +9.81 along the sensor's up axis. */
typedef struct procam_tilt_sample {
  double specific_force[3];
  uint64_t timestamp_ns;
} procam_tilt_sample;

/* A tilt driver gates its own samples: read() drops a garbage sample (not
 * finite, outside the sensor's range, stuck, |f| far from 1 g) and returns
 * PROCAM_EAGAIN; the daemon does not gate the samples read() returns again. These
 * are the driver's counts since the device was created. */
typedef struct procam_tilt_counts {
  uint64_t accepted;     /* samples read() returned */
  uint64_t not_finite;   /* rejected: NaN, Inf or no number at all */
  uint64_t out_of_range; /* rejected: a component beyond the sensor's range */
  uint64_t stuck;        /* rejected: the same reading too many times in a row */
  uint64_t bad_norm;     /* rejected: |specific force| far from 1 g */
} procam_tilt_counts;

/* A gyroscope in the tilt sensor's package (an MPU-6050, an IIO device with
 * anglvel channels, a HID sensor hub): angular velocity in the sensor frame,
 * rad/s, right-handed about each sensor axis. */
typedef struct procam_rate_sample {
  double angular_velocity[3];
  uint64_t timestamp_ns;
} procam_rate_sample;

typedef struct procam_tilt_ops {
  uint32_t version; /* PROCAM_TILT_OPS_VERSION */
  int (*read)(void* self, procam_tilt_sample* out, char* err, size_t err_len);
  /* Version 2, optional (may be NULL): fills `out` with the driver's counts.
   * The daemon reads this member only from a table of version 2 or later. */
  int (*get_counts)(void* self, procam_tilt_counts* out);
  /* Version 3, optional (may be NULL): the gyroscope's reading taken with the
   * sample read() last returned; PROCAM_ENOTSUP when the sensor has none. Called
   * right after read(), on the same thread. The daemon reads this member only
   * from a table of version 3 or later. */
  int (*read_rate)(void* self, procam_rate_sample* out, char* err, size_t err_len);
} procam_tilt_ops;

/* Head tracker: viewer position in the world frame (metres) and orientation
 * as a unit quaternion (w, x, y, z). */
typedef struct procam_pose_sample {
  double position[3];
  double orientation[4];
  uint64_t timestamp_ns;
} procam_pose_sample;

typedef struct procam_tracker_ops {
  uint32_t version; /* PROCAM_TRACKER_OPS_VERSION */
  int (*read)(void* self, procam_pose_sample* out, char* err, size_t err_len);
  /* Optional (may be NULL): the tracker's own sample rate in Hz, so that the
   * daemon polls it no faster than it reports; PROCAM_ENOTSUP when unknown. */
  int (*get_rate)(void* self, double* out_hz);
} procam_tracker_ops;

/* Projector output.
 *
 * Version 1: `get_mode` and `show`, one full frame of the mode's size shown 1:1
 * (calibration patterns, latency probes).
 *
 * Version 2 adds rendering by the output itself: the daemon hands over the
 * geometry once (`configure`, a render setup: which path, its matrices, meshes,
 * warp grids, the blending stage) and then the content (`render`), and the
 * output draws the frame on its own back-end (GLES outputs on the GPU, CPU
 * outputs with a warp map built once per setup). `configure` is called again
 * only when the geometry changes; `render` re-draws only when the content's
 * version or the geometry changed since the last frame. Everything a setup or
 * content points to is only valid during the call: an output copies what it
 * keeps. Paths, matrices and conventions: ARCHITECTURE.md ("Rendering"). */
typedef enum procam_render_path {
  PROCAM_RENDER_HOMOGRAPHY = 1,    /* projector pixel ~ H content pixel */
  PROCAM_RENDER_PLANAR_3D = 2,     /* mesh content through A'4x4 (world -> pixel, depth) */
  PROCAM_RENDER_TWO_PASS_MESH = 3, /* content = the viewer's image, projected on the surface */
  PROCAM_RENDER_LOOKUP_WARP = 4    /* per-node content coordinates of every output pixel */
} procam_render_path;

/* A warp grid: `cols` x `rows` nodes (>= 2 each) at output pixels origin + (i, j) step,
 * each holding the source pixel it shows as (x, y) in `source`, row-major. Between
 * nodes the warp is linear over two triangles per cell split from node (i, j) to
 * (i + 1, j + 1). cols == 0: no grid. */
typedef struct procam_warp_grid {
  uint32_t cols, rows;
  double origin[2];
  double step[2];
  const double* source;
} procam_warp_grid;

typedef struct procam_render_setup {
  uint32_t output_width, output_height;   /* the output's mode */
  uint32_t content_width, content_height; /* image paths */
  procam_render_path path;
  double homography[9]; /* HOMOGRAPHY, row-major */
  double planar3d[16];  /* PLANAR_3D, row-major: world -> (x w, y w, z w, w), z in [-1, 1] */
  /* TWO_PASS_MESH: the display surface (world, metres) and the 3x4 row-major
   * world -> projector and world -> content pixel matrices. */
  const double* surface_vertices; /* 3 per vertex */
  size_t n_surface_vertices;
  const int32_t* surface_triangles; /* 3 per triangle */
  size_t n_surface_triangles;
  double projector[12];
  double viewer[12];
  procam_warp_grid lookup;    /* LOOKUP_WARP */
  procam_warp_grid post_warp; /* optional, any path: output pixel -> rendered pixel */
  /* The final stage, always last: alpha mask (output size, NULL = all 255), weight
   * LUT (256 entries, NULL = identity), output LUT (3 x 256, R then G then B; NULL =
   * identity): w = weight_lut[alpha], v = (c w + 127) / 255, out = output_lut[c][v]. */
  const uint8_t* alpha;
  uint32_t alpha_stride;
  const uint8_t* weight_lut;
  const uint8_t* output_lut;
} procam_render_setup;

/* Content for `render`: an RGBA8 image of the setup's content size (image paths) or
 * a mesh with one RGBA colour per vertex (PLANAR_3D). `version` changes whenever the
 * content changes: an output uploads content only when it does. */
typedef struct procam_content {
  const procam_image* image;
  const double* mesh_vertices; /* 3 per vertex, world metres */
  const uint8_t* mesh_colors;  /* 4 per vertex */
  size_t n_mesh_vertices;
  const int32_t* mesh_triangles; /* 3 per triangle */
  size_t n_mesh_triangles;
  uint64_t version;
} procam_content;

/* What a frame holds, for status: the fraction of pixels with any colour channel
 * above 0 and the mean of R, G, B (0..255). */
typedef struct procam_frame_stats {
  double lit_fraction;
  double mean_rgb[3];
} procam_frame_stats;

typedef struct procam_output_ops {
  uint32_t version; /* PROCAM_OUTPUT_OPS_VERSION */
  int (*get_mode)(void* self, uint32_t* out_width, uint32_t* out_height, double* out_refresh_hz);
  /* Shows one frame 1:1 (RGB8, RGBA8 or GRAY8 of the mode's size); the frame
   * replaces whatever `render` drew until the next `render`. */
  int (*show)(void* self, const procam_image* frame, char* err, size_t err_len);
  /* Version 2. */
  int (*configure)(void* self, const procam_render_setup* setup, char* err, size_t err_len);
  /* Draws and presents the content through the configured setup. `*out_drawn` = 1
   * when a frame was drawn, 0 when neither content version nor geometry changed.
   * `stats` may be NULL; when not, it receives the current frame's statistics
   * (drawn or not), which may cost a GPU read-back. */
  int (*render)(void* self, const procam_content* content, int* out_drawn,
                procam_frame_stats* stats, char* err, size_t err_len);
  /* Version 3. As `render`, but the plugin calls `stop(stop_ctx)` between the steps
   * of its drawing (from any of the threads it draws with, possibly at once: `stop`
   * must be thread-safe; for a mesh, every few thousand triangles) and, once it
   * returns nonzero, stops: PROCAM_ECANCELED, nothing
   * presented, the frame shown before stays, and the next render draws in full.
   * `stop` may be NULL (never stop). The daemon stops a frame that a newer request
   * (other content, a pattern a client waits for) has made obsolete. */
  int (*render_stoppable)(void* self, const procam_content* content, int (*stop)(void* stop_ctx),
                          void* stop_ctx, int* out_drawn, procam_frame_stats* stats, char* err,
                          size_t err_len);
  /* Version 4, both optional (may be NULL). `present_at`: the next frame `render`
   * draws goes on screen no earlier than `not_before_ns` (CLOCK_MONOTONIC; 0: as soon
   * as it is drawn, the default); an output that presents at its display's vblank
   * presents at the first vblank at or after it. `render` returns once the frame is
   * drawn: either once it is on screen or with it queued to go on at the time
   * `get_timing` gives, so that the next frame can be drawn meanwhile. The daemon
   * predicts a moving projector's pose to that instant. */
  int (*present_at)(void* self, uint64_t not_before_ns);
  /* About the last frame `render` drew: when its drawing ended (`out_ready_ns`) and
   * when it goes on screen (`out_shown_ns`), CLOCK_MONOTONIC, 0 before the first; the
   * display's refresh period for an output that presents at vblank (`out_period_ns`),
   * else 0. */
  int (*get_timing)(void* self, uint64_t* out_ready_ns, uint64_t* out_shown_ns,
                    uint64_t* out_period_ns);
} procam_output_ops;

/* A created device. `poll_fd` returns a file descriptor the daemon may watch
 * for readability (new data), or -1 when the device is polled by timer.
 * `destroy` releases everything; the daemon calls it exactly once. */
typedef struct procam_device {
  procam_family family;
  void* self;
  int (*poll_fd)(void* self);
  void (*destroy)(void* self);
  union {
    const procam_camera_ops* camera;
    const procam_tilt_ops* tilt;
    const procam_tracker_ops* tracker;
    const procam_output_ops* output;
  } ops;
} procam_device;

/* One driver. `probe` scores how well the driver handles a device: 0 means
 * "not mine", higher wins (hardware drivers use 1..99, simulated drivers 100+
 * so that they outrank hardware when enabled). `create` fills `out`.
 *
 * `enumerate` (may be NULL) lists devices the driver provides by itself,
 * without udev or configuration: the virtual rig's mock devices, a replayed
 * recording. The daemon calls it at start with the driver's options (for the
 * virtual rig: "scene"), then opens each listed device with probe/create like
 * any other. On PROCAM_OK `*out_devices` points to `*out_n` descriptions owned
 * by the plugin and valid until the next enumerate call or unload; a driver
 * with nothing to offer for these options returns PROCAM_OK and 0 devices. */
typedef struct procam_driver_factory {
  procam_family family;
  const char* name;
  const char* description;
  int (*probe)(const procam_device_desc* device);
  int (*create)(const procam_device_desc* device, const procam_config* config, procam_device* out,
                char* err, size_t err_len);
  int (*enumerate)(const procam_config* config, const procam_device_desc** out_devices,
                   size_t* out_n, char* err, size_t err_len);
} procam_driver_factory;

typedef struct procam_plugin_table {
  uint32_t abi_version; /* PROCAM_PLUGIN_ABI_VERSION again, checked a second time */
  const char* plugin_name;
  const char* plugin_version;
  size_t n_factories;
  const procam_driver_factory* factories;
} procam_plugin_table;

typedef const procam_plugin_table* (*procam_plugin_entry_fn)(void);

#ifdef __cplusplus
#define PROCAM_PLUGIN_EXTERN_C extern "C"
#else
#define PROCAM_PLUGIN_EXTERN_C
#endif

/* Defines the two exported symbols of a shared-object plugin. */
#define PROCAM_PLUGIN_DEFINE(entry_function)                                               \
  PROCAM_PLUGIN_EXTERN_C __attribute__((visibility("default")))                            \
  const uint32_t procam_plugin_abi_version = PROCAM_PLUGIN_ABI_VERSION;                    \
  PROCAM_PLUGIN_EXTERN_C __attribute__((visibility("default"))) const procam_plugin_table* \
  procam_plugin_entry(void) {                                                              \
    return entry_function();                                                               \
  }

#ifdef __cplusplus
}
#endif

#endif /* PROCAMD_PROCAM_PLUGIN_H */
