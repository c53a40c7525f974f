/*
 * avatarmap C API: MediaPipe landmarks -> proxy pose of the 55 VRM 1.0 humanoid bones.
 *
 * C99, usable from C, C++ and any FFI (ctypes, cffi, P/Invoke, ...).
 *
 * Conventions
 *   - Every function returns an avm_status, a plain value or nothing; no function throws,
 *     aborts or calls exit(). A NULL pointer where an object is required gives
 *     AVM_ERROR_INVALID_ARGUMENT, never a crash.
 *   - Handles are typed and opaque (avm_solver, avm_retargeter, avm_clip). A handle is
 *     created by its *_create() function, owned by the caller and freed by its *_destroy();
 *     destroying NULL does nothing.
 *   - The library never hands out memory the caller must free. Strings it returns are either
 *     static (valid for the life of the process) or owned by a handle (valid until the next
 *     call on that handle or its destruction) as stated on each function.
 *   - Threads: a handle must be used from one thread at a time (calls on one handle must not
 *     overlap); different handles are fully independent and may be used from different
 *     threads at once. Functions without a handle are thread-safe.
 *   - Quaternions cross this boundary as {x, y, z, w}. Rotations are local (relative to the
 *     parent bone) in VRM 1.0 normalised space: identity = VRM T-pose, Y up, the avatar faces
 *     +Z, the avatar's left is +X. Positions are metres; times are seconds.
 *   - Evolution: structs whose layout may grow start with `uint32_t struct_size`; new
 *     behaviour comes as new fields at the end of such structs or as new `_v2` functions.
 */
#ifndef AVATARMAP_AVATARMAP_H
#define AVATARMAP_AVATARMAP_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32) || defined(__CYGWIN__)
#if defined(AVATARMAP_C_BUILDING)
#define AVATARMAP_C_API __declspec(dllexport)
#else
#define AVATARMAP_C_API __declspec(dllimport)
#endif
#elif defined(AVATARMAP_C_BUILDING) && (defined(__GNUC__) || defined(__clang__))
#define AVATARMAP_C_API __attribute__((visibility("default")))
#else
#define AVATARMAP_C_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- version ------------------------------------------------------------------------- */

/* Version of this header. avm_version() gives the version of the library actually loaded;
 * they differ only when a program runs against another build of the shared library. */
#define AVM_VERSION_MAJOR 0
#define AVM_VERSION_MINOR 2
#define AVM_VERSION_PATCH 0
#define AVM_VERSION_STRING "0.2.0"
/* Single number for compile-time comparisons: MAJOR * 10000 + MINOR * 100 + PATCH. */
#define AVM_VERSION_NUMBER (AVM_VERSION_MAJOR * 10000 + AVM_VERSION_MINOR * 100 + AVM_VERSION_PATCH)

/* Writes the loaded library's version into each non-NULL argument (NULL ones are skipped).
 * Thread-safe; cannot fail. */
AVATARMAP_C_API void avm_version(int* out_major, int* out_minor, int* out_patch);

/* The loaded library's version as "MAJOR.MINOR.PATCH". Static string; thread-safe. */
AVATARMAP_C_API const char* avm_version_string(void);

/* ---- status -------------------------------------------------------------------------- */

/* Each failure of the library has a kind, and each kind its own status, one to one (the
 * kinds and when they occur: docs/c-api.md, "Errors"). */

typedef enum avm_status {
  AVM_OK = 0,
  AVM_ERROR_INVALID_ARGUMENT, /* NULL pointer, bad count, option out of range, ... */
  AVM_ERROR_IO,               /* a file could not be opened, written or renamed */
  AVM_ERROR_PARSE,            /* a file's content is malformed */
  AVM_ERROR_END_OF_FILE,      /* no more data (not a failure of the caller) */
  AVM_ERROR_UNSUPPORTED,      /* the feature is not available in this build */
  AVM_ERROR_OUT_OF_MEMORY,    /* an allocation failed */
  AVM_ERROR_INTERNAL          /* a bug in avatarmap: please report it with last_error */
} avm_status;

/* Short English description of a status ("ok", "invalid argument", ...); "unknown status"
 * for values outside the enum. Static string; thread-safe. */
AVATARMAP_C_API const char* avm_status_string(avm_status status);

/* ---- limits (include/avatarmap/core/limits.hpp; the library checks they are equal) ------ */

/* The highest frame rate any call accepts, frames per second (avm_clip_write's fps, ...). */
#define AVM_MAX_FPS 1000.0
/* The most threads avm_estimator_options.threads may ask for. */
#define AVM_MAX_MODEL_THREADS 64
/* The most people avm_estimator_options.max_people may ask for. */
#define AVM_MAX_PEOPLE 8

/* ---- skeleton vocabulary ------------------------------------------------------------- */

#define AVM_BONE_COUNT 55
#define AVM_EXPRESSION_COUNT 21 /* 16 before 0.2.0 */
#define AVM_BLENDSHAPE_COUNT 52 /* ARKit's face blendshapes (added in 0.2.0) */

/* Bones in the order of avm_pose's arrays: every parent comes before its children. */
typedef enum avm_bone {
  AVM_BONE_HIPS = 0,
  AVM_BONE_SPINE,
  AVM_BONE_CHEST,
  AVM_BONE_UPPER_CHEST,
  AVM_BONE_NECK,
  AVM_BONE_HEAD,
  AVM_BONE_LEFT_EYE,
  AVM_BONE_RIGHT_EYE,
  AVM_BONE_JAW,
  AVM_BONE_LEFT_UPPER_LEG,
  AVM_BONE_LEFT_LOWER_LEG,
  AVM_BONE_LEFT_FOOT,
  AVM_BONE_LEFT_TOES,
  AVM_BONE_RIGHT_UPPER_LEG,
  AVM_BONE_RIGHT_LOWER_LEG,
  AVM_BONE_RIGHT_FOOT,
  AVM_BONE_RIGHT_TOES,
  AVM_BONE_LEFT_SHOULDER,
  AVM_BONE_LEFT_UPPER_ARM,
  AVM_BONE_LEFT_LOWER_ARM,
  AVM_BONE_LEFT_HAND,
  AVM_BONE_RIGHT_SHOULDER,
  AVM_BONE_RIGHT_UPPER_ARM,
  AVM_BONE_RIGHT_LOWER_ARM,
  AVM_BONE_RIGHT_HAND,
  AVM_BONE_LEFT_THUMB_METACARPAL,
  AVM_BONE_LEFT_THUMB_PROXIMAL,
  AVM_BONE_LEFT_THUMB_DISTAL,
  AVM_BONE_LEFT_INDEX_PROXIMAL,
  AVM_BONE_LEFT_INDEX_INTERMEDIATE,
  AVM_BONE_LEFT_INDEX_DISTAL,
  AVM_BONE_LEFT_MIDDLE_PROXIMAL,
  AVM_BONE_LEFT_MIDDLE_INTERMEDIATE,
  AVM_BONE_LEFT_MIDDLE_DISTAL,
  AVM_BONE_LEFT_RING_PROXIMAL,
  AVM_BONE_LEFT_RING_INTERMEDIATE,
  AVM_BONE_LEFT_RING_DISTAL,
  AVM_BONE_LEFT_LITTLE_PROXIMAL,
  AVM_BONE_LEFT_LITTLE_INTERMEDIATE,
  AVM_BONE_LEFT_LITTLE_DISTAL,
  AVM_BONE_RIGHT_THUMB_METACARPAL,
  AVM_BONE_RIGHT_THUMB_PROXIMAL,
  AVM_BONE_RIGHT_THUMB_DISTAL,
  AVM_BONE_RIGHT_INDEX_PROXIMAL,
  AVM_BONE_RIGHT_INDEX_INTERMEDIATE,
  AVM_BONE_RIGHT_INDEX_DISTAL,
  AVM_BONE_RIGHT_MIDDLE_PROXIMAL,
  AVM_BONE_RIGHT_MIDDLE_INTERMEDIATE,
  AVM_BONE_RIGHT_MIDDLE_DISTAL,
  AVM_BONE_RIGHT_RING_PROXIMAL,
  AVM_BONE_RIGHT_RING_INTERMEDIATE,
  AVM_BONE_RIGHT_RING_DISTAL,
  AVM_BONE_RIGHT_LITTLE_PROXIMAL,
  AVM_BONE_RIGHT_LITTLE_INTERMEDIATE,
  AVM_BONE_RIGHT_LITTLE_DISTAL
} avm_bone;

/* Expressions in the order of avm_pose's expressions array (VRM 1.0 preset names plus four
 * custom brow expressions; the five emotions were appended in 0.2.0). "Left" is the person's
 * and the avatar's left. */
typedef enum avm_expression {
  AVM_EXPRESSION_BLINK = 0,
  AVM_EXPRESSION_BLINK_LEFT,
  AVM_EXPRESSION_BLINK_RIGHT,
  AVM_EXPRESSION_AA,
  AVM_EXPRESSION_IH,
  AVM_EXPRESSION_OU,
  AVM_EXPRESSION_EE,
  AVM_EXPRESSION_OH,
  AVM_EXPRESSION_LOOK_UP,
  AVM_EXPRESSION_LOOK_DOWN,
  AVM_EXPRESSION_LOOK_LEFT,
  AVM_EXPRESSION_LOOK_RIGHT,
  AVM_EXPRESSION_BROW_UP_LEFT,
  AVM_EXPRESSION_BROW_UP_RIGHT,
  AVM_EXPRESSION_BROW_DOWN_LEFT,
  AVM_EXPRESSION_BROW_DOWN_RIGHT,
  AVM_EXPRESSION_HAPPY, /* VRM 1.0 emotion presets (0.2.0) */
  AVM_EXPRESSION_ANGRY,
  AVM_EXPRESSION_SAD,
  AVM_EXPRESSION_RELAXED,
  AVM_EXPRESSION_SURPRISED
} avm_expression;

/* ARKit's 52 face blendshapes in the order of avm_pose's blendshapes array: Apple's
 * ARFaceAnchor.BlendShapeLocation names and meanings, in Apple's alphabetical order (also
 * MediaPipe's face landmarker's). "Left" is the person's own left. Weights 0 .. 1.
 * docs/expressions.md defines how each is measured. Added in 0.2.0. */
typedef enum avm_blendshape {
  AVM_BLENDSHAPE_BROW_DOWN_LEFT = 0,
  AVM_BLENDSHAPE_BROW_DOWN_RIGHT,
  AVM_BLENDSHAPE_BROW_INNER_UP,
  AVM_BLENDSHAPE_BROW_OUTER_UP_LEFT,
  AVM_BLENDSHAPE_BROW_OUTER_UP_RIGHT,
  AVM_BLENDSHAPE_CHEEK_PUFF,
  AVM_BLENDSHAPE_CHEEK_SQUINT_LEFT,
  AVM_BLENDSHAPE_CHEEK_SQUINT_RIGHT,
  AVM_BLENDSHAPE_EYE_BLINK_LEFT,
  AVM_BLENDSHAPE_EYE_BLINK_RIGHT,
  AVM_BLENDSHAPE_EYE_LOOK_DOWN_LEFT,
  AVM_BLENDSHAPE_EYE_LOOK_DOWN_RIGHT,
  AVM_BLENDSHAPE_EYE_LOOK_IN_LEFT,
  AVM_BLENDSHAPE_EYE_LOOK_IN_RIGHT,
  AVM_BLENDSHAPE_EYE_LOOK_OUT_LEFT,
  AVM_BLENDSHAPE_EYE_LOOK_OUT_RIGHT,
  AVM_BLENDSHAPE_EYE_LOOK_UP_LEFT,
  AVM_BLENDSHAPE_EYE_LOOK_UP_RIGHT,
  AVM_BLENDSHAPE_EYE_SQUINT_LEFT,
  AVM_BLENDSHAPE_EYE_SQUINT_RIGHT,
  AVM_BLENDSHAPE_EYE_WIDE_LEFT,
  AVM_BLENDSHAPE_EYE_WIDE_RIGHT,
  AVM_BLENDSHAPE_JAW_FORWARD,
  AVM_BLENDSHAPE_JAW_LEFT,
  AVM_BLENDSHAPE_JAW_OPEN,
  AVM_BLENDSHAPE_JAW_RIGHT,
  AVM_BLENDSHAPE_MOUTH_CLOSE,
  AVM_BLENDSHAPE_MOUTH_DIMPLE_LEFT,
  AVM_BLENDSHAPE_MOUTH_DIMPLE_RIGHT,
  AVM_BLENDSHAPE_MOUTH_FROWN_LEFT,
  AVM_BLENDSHAPE_MOUTH_FROWN_RIGHT,
  AVM_BLENDSHAPE_MOUTH_FUNNEL,
  AVM_BLENDSHAPE_MOUTH_LEFT,
  AVM_BLENDSHAPE_MOUTH_LOWER_DOWN_LEFT,
  AVM_BLENDSHAPE_MOUTH_LOWER_DOWN_RIGHT,
  AVM_BLENDSHAPE_MOUTH_PRESS_LEFT,
  AVM_BLENDSHAPE_MOUTH_PRESS_RIGHT,
  AVM_BLENDSHAPE_MOUTH_PUCKER,
  AVM_BLENDSHAPE_MOUTH_RIGHT,
  AVM_BLENDSHAPE_MOUTH_ROLL_LOWER,
  AVM_BLENDSHAPE_MOUTH_ROLL_UPPER,
  AVM_BLENDSHAPE_MOUTH_SHRUG_LOWER,
  AVM_BLENDSHAPE_MOUTH_SHRUG_UPPER,
  AVM_BLENDSHAPE_MOUTH_SMILE_LEFT,
  AVM_BLENDSHAPE_MOUTH_SMILE_RIGHT,
  AVM_BLENDSHAPE_MOUTH_STRETCH_LEFT,
  AVM_BLENDSHAPE_MOUTH_STRETCH_RIGHT,
  AVM_BLENDSHAPE_MOUTH_UPPER_UP_LEFT,
  AVM_BLENDSHAPE_MOUTH_UPPER_UP_RIGHT,
  AVM_BLENDSHAPE_NOSE_SNEER_LEFT,
  AVM_BLENDSHAPE_NOSE_SNEER_RIGHT,
  AVM_BLENDSHAPE_TONGUE_OUT
} avm_blendshape;

/* VRM 1.0 name of a bone ("hips", "leftUpperArm", ...); NULL when `bone` is outside
 * [0, AVM_BONE_COUNT). Static string; thread-safe. */
AVATARMAP_C_API const char* avm_bone_name(int bone);

/* Parent of a bone; -1 for hips (the root) and for `bone` outside [0, AVM_BONE_COUNT).
 * Thread-safe. */
AVATARMAP_C_API int avm_bone_parent(int bone);

/* Bone index from its exact, case-sensitive VRM 1.0 name; -1 when unknown or `name` is NULL.
 * Thread-safe. */
AVATARMAP_C_API int avm_bone_from_name(const char* name);

/* Name of an expression as written in *.pose.jsonl ("blink", "blinkLeft", "aa", ...); NULL
 * when `expression` is outside [0, AVM_EXPRESSION_COUNT). Static string; thread-safe. */
AVATARMAP_C_API const char* avm_expression_name(int expression);

/* Expression index from its exact name; -1 when unknown or `name` is NULL. Thread-safe. */
AVATARMAP_C_API int avm_expression_from_name(const char* name);

/* ARKit name of a blendshape as written in *.pose.jsonl ("browDownLeft", "jawOpen", ...);
 * NULL when `blendshape` is outside [0, AVM_BLENDSHAPE_COUNT). Static string; thread-safe.
 * Added in 0.2.0. */
AVATARMAP_C_API const char* avm_blendshape_name(int blendshape);

/* Blendshape index from its exact, case-sensitive ARKit name; -1 when unknown or `name` is
 * NULL. Thread-safe. Added in 0.2.0. */
AVATARMAP_C_API int avm_blendshape_from_name(const char* name);

/* ---- input: one frame of landmarks --------------------------------------------------- */

#define AVM_POSE_LANDMARK_COUNT 33
#define AVM_HAND_LANDMARK_COUNT 21
#define AVM_FACE_LANDMARK_COUNT 468      /* face mesh */
#define AVM_FACE_IRIS_LANDMARK_COUNT 478 /* face mesh with iris refinement */

/* One MediaPipe landmark. Image points: x, y normalised to [0, 1] of the image width and
 * height (y down), z relative depth. World points: metres, x toward image right, y down,
 * z away from the camera. visibility and presence are in [0, 1]; give 1 for both on hand and
 * face points (a landmark whose min(visibility, presence) is low is treated as not seen).
 * Non-finite values (NaN, inf) are accepted and mean "not seen". */
typedef struct avm_landmark {
  float x;
  float y;
  float z;
  float visibility;
  float presence;
} avm_landmark;

/* One captured frame. Each pointer is either NULL (the part was not seen) or points to the
 * stated number of landmarks; "left"/"right" are the person's anatomical sides. The arrays
 * are only read during the call that receives the frame; they are not retained. */
typedef struct avm_frame {
  double t;                             /* capture time, seconds; must be finite */
  const avm_landmark* pose;             /* AVM_POSE_LANDMARK_COUNT image points */
  const avm_landmark* pose_world;       /* AVM_POSE_LANDMARK_COUNT world points */
  const avm_landmark* left_hand;        /* AVM_HAND_LANDMARK_COUNT image points */
  const avm_landmark* left_hand_world;  /* AVM_HAND_LANDMARK_COUNT world points */
  const avm_landmark* right_hand;       /* AVM_HAND_LANDMARK_COUNT image points */
  const avm_landmark* right_hand_world; /* AVM_HAND_LANDMARK_COUNT world points */
  const avm_landmark* face;             /* face_count image points */
  int32_t face_count; /* AVM_FACE_LANDMARK_COUNT or AVM_FACE_IRIS_LANDMARK_COUNT when face
                         is not NULL; ignored when face is NULL */
} avm_frame;

/* ---- output: one proxy pose ---------------------------------------------------------- */

typedef struct avm_pose {
  double t;                           /* seconds: the frame's capture time, or the sampled time */
  float hips_position[3];             /* metres, VRM space: Y = hips height above the soles */
  float rotations[AVM_BONE_COUNT][4]; /* local rotation {x, y, z, w}, unit length */
  float confidence[AVM_BONE_COUNT];   /* 0 = not observed .. 1 = observed */
  /* Weights 0 .. 1, see avm_expression. Changed in 0.2.0: 21 instead of 16 (the five
   * emotions appended), which moves every member after it: rebuild against this header. */
  float expressions[AVM_EXPRESSION_COUNT];
  /* Added in 0.1.0 at the end (the struct grew by 8 bytes: arrays of avm_pose built against
   * an older header have another stride; rebuild against this one). Per foot, [0] left
   * [1] right: 0 = the foot moves freely .. 1 = planted on the floor (docs/contacts.md);
   * values between blend foot locking in and out. Read by avm_clip_write (clamped to
   * [0, 1], NaN = 0). */
  float foot_contact[2];
  /* Added in 0.2.0 at the end (with the 5 new expressions the struct grew by 228 bytes:
   * changed in 0.2.0: rebuild). ARKit's 52 blendshape weights 0 .. 1, see avm_blendshape;
   * all 0 when the face was not solved. Taken like expressions wherever a pose goes in
   * (a non-finite weight is missing: the previous frame's, 0 for the first). */
  float blendshapes[AVM_BLENDSHAPE_COUNT];
  /* (On the usual ABIs 4 bytes of padding follow, sizeof(avm_pose) = 1424; the library writes
   * them as 0 in every pose it gives out.) */
} avm_pose;

/* ---- solver options ------------------------------------------------------------------ */

/* Options of a solver. Always initialise with avm_solver_options_init() and then change
 * fields: it sets struct_size, which lets a library built with more fields than the caller
 * knows fill the rest with defaults, and lets this library read only the fields it knows
 * from a caller compiled against a newer header. Booleans are int32_t, 0 or non-zero.
 * Ranges are checked by avm_solver_create() / avm_solve_file().
 * Writing the defaults never goes past the caller's struct: avm_solver_options_init() is a
 * macro passing sizeof(avm_solver_options) as this header knows it to
 * avm_solver_options_init_sized(), so a program built against an older, shorter struct keeps
 * working with a newer library. Bindings that mirror the struct (ctypes, cffi, P/Invoke) call
 * avm_solver_options_init_sized() with their mirror's size. */
typedef struct avm_solver_options {
  uint32_t struct_size; /* sizeof(avm_solver_options) as the caller knows it */

  /* -- solver (see include/avatarmap/solve/solver_options.hpp) -- */
  int32_t mirror;      /* swap left and right and flip X (mirrored webcam preview); 0 */
  float image_width;   /* pixels; 0 = unknown (square pixels assumed); give both or neither */
  float image_height;  /* pixels; 0 */
  int32_t solve_body;  /* hips, spine, shoulders, arms, legs, feet; 1 */
  int32_t solve_hands; /* wrists' orientation and fingers; 1 */
  int32_t solve_face;  /* neck, head, eyes, expressions; 1 */
  int32_t solve_hips_translation;  /* hips_position X/Y/Z from the image (else rest); 1 */
  float confidence_lost_below;     /* a bone is lost below this confidence; 0.3 */
  float confidence_found_above;    /* ... and found again above this; 0.5 (>= lost_below) */
  float confidence_hold_seconds;   /* a lost bone holds its last rotation this long; 0.5 */
  float confidence_ease_seconds;   /* ... then eases to rest over this long; 1.0 */
  float confidence_regain_seconds; /* a found bone blends in over this long; 0.15 */
  float hips_lean_share;           /* [0, 1] share of the torso lean given to the hips; 0.5 */
  float forearm_twist_share;       /* [0, 1] share of wrist twist moved to the forearm; 0.6 */
  float horizontal_fov_degrees;    /* camera's horizontal field of view, (1, 179), or 0 (the
                                      default): estimated from the pose's image and world points
                                      (needs the image size; 60 until the pose tells better) */
  float rest_hips_height;          /* metres, (0, 10), used while legs were never seen; 0.95 */

  /* -- One Euro filter applied to each solved pose (avm_solver_push, avm_solve_file);
   *    defaults from include/avatarmap/time/pose_filter.hpp. Cutoffs in Hz, finite, > 0;
   *    betas finite, >= 0 (rotation: seconds per radian, position: seconds per metre,
   *    expressions: seconds per unit weight). -- */
  int32_t filter_rotations;    /* filter the bone rotations; 1 */
  float rotation_min_cutoff;   /* 0.7 (plus pose_filter.hpp's 3/4-lag extrapolation) */
  float rotation_beta;         /* 0.3 */
  float rotation_d_cutoff;     /* cutoff of the speed estimate; 1.0 */
  int32_t filter_position;     /* filter hips_position; 1 */
  float position_min_cutoff;   /* 1.0 */
  float position_beta;         /* 2.0 */
  float position_d_cutoff;     /* 1.0 */
  int32_t filter_expressions;  /* filter the expression and blendshape weights; 1 */
  float expression_min_cutoff; /* 3.0 */
  float expression_beta;       /* 1.0 */
  float expression_d_cutoff;   /* 1.0 */

  /* -- resampler (avm_solver_sample) -- */
  float max_extrapolation_seconds; /* finite, >= 0: how far past the newest frame sample()
                                      extrapolates before holding still; 0.1 */

  /* -- how avm_solve_file smooths a whole file (docs/smoothing.md); the per-frame path
   *    (avm_solver_push) always uses the One Euro filter above. Added in 0.1.0 after the
   *    fields above: a caller whose struct_size ends before them gets the defaults. -- */
  int32_t file_filter;  /* avm_file_filter; AVM_FILE_FILTER_OFFLINE */
  float file_smoothing; /* offline: scale on the smoothing time constants, finite, [0, 6.66]
                           (the widest kernel at most 2 s; 0 = fill gaps only); 1 */
  /* -- added in 0.1.0 after file_smoothing (a caller whose struct_size ends before it gets
   *    the default) -- */
  int32_t file_threads; /* threads of avm_solve_file / avm_solve_file_to_clip: 2 parses the
                           file ahead on a second thread (the default, as `avatarmap solve`);
                           1 does everything on the calling thread (one task per core, e.g.
                           a batch's workers) */
  /* -- added in 0.1.0 after file_threads (a caller whose struct_size ends before it gets the
   *    default) -- */
  int32_t fit_hand_shape; /* fit each hand's world landmarks to its shape learnt over the take
                             (a rigid palm, fingers of constant length; docs/solver.md "The
                             hand's shape"): less finger noise, exact landmarks unchanged; 1 */
  /* -- added in 0.1.0 after fit_hand_shape (a caller whose struct_size ends before it gets
   *    the default) -- */
  int32_t fit_body_to_image; /* fit the body's world points to its image points through the
                                camera with the take's bone lengths, and turn it upright by
                                the camera's pitch and roll (docs/solver.md "The body in the
                                world"); needs image_width/height; 1 */
  /* -- added in 0.1.0 after fit_body_to_image (a caller whose struct_size ends before them
   *    gets the defaults) -- */
  /* Detect planted feet (avm_pose.foot_contact; docs/contacts.md): both-sided in
   * avm_solve_file's offline filter, causal without delay on the per-frame path; 0 =
   * foot_contact 0 and the hips as filtered; 1 */
  int32_t foot_contacts;
  /* With foot_contacts: move the hips so that a planted foot stays where it landed (0: only
   * foot_contact is written); 1 */
  int32_t root_follows_contacts;
  /* -- added in 0.1.0 after root_follows_contacts (a caller whose struct_size ends before it
   *    gets the default) -- */
  /* Where the lower body (hips, legs, feet, root) is held on frames whose body's points are
   * not a person's (legs above the hips, a torso larger than the image, impossible bone
   * lengths) or whose legs are not seen (upper-body framing), with a few frames of
   * hysteresis; arms, hands and face still drive (docs/solver.md "Bodies that are not
   * followed"): 0 standing (default), 1 sitting, 2 off (follow every body) */
  int32_t lower_body_rest;
  /* -- added in 0.2.0 after lower_body_rest (a caller whose struct_size ends before it gets
   *    the default) -- */
  /* Of a landmark file of several people (docs/file-formats.md, version 2), the person
   * avm_solve_file, avm_solve_file_to_clip and avm_convert_file solve: its id in
   * [0, 999999]; -1 (default): the file's only person (a file of several is then an error
   * that lists their ids) */
  int32_t person;
} avm_solver_options;

/* What avm_solve_file does after solving each frame. */
typedef enum avm_file_filter {
  /* Zero-lag smoothing that sees 1.5 s ahead, and bones not observed for up to 1.5 s filled
   * from both sides (longer gaps ease to rest); the confidence_* thresholds above are not
   * used (the smoother decides what was observed); hold and ease times are its own. */
  AVM_FILE_FILTER_OFFLINE = 0,
  /* The causal One Euro filter above, as avm_solver_push() applies it (the behaviour of
   * avm_solve_file before file_filter existed). */
  AVM_FILE_FILTER_LIVE = 1,
  /* No smoothing after solving (the confidence gate above still applies). */
  AVM_FILE_FILTER_NONE = 2
} avm_file_filter;

/* Fills the first `size` bytes of `options` with the defaults (size = the caller's
 * sizeof(avm_solver_options); bytes past this library's struct are left as they are) and sets
 * options->struct_size = size. Returns AVM_ERROR_INVALID_ARGUMENT when `options` is NULL or
 * size is below 8, above 4096 or not a multiple of 4. Thread-safe. */
AVATARMAP_C_API avm_status avm_solver_options_init_sized(avm_solver_options* options, size_t size);

/* Fills `options` with the defaults and sets options->struct_size, writing
 * sizeof(avm_solver_options) bytes of this library's struct (the function, for binaries built
 * before the macro below). Returns AVM_ERROR_INVALID_ARGUMENT when `options` is NULL.
 * Thread-safe. */
AVATARMAP_C_API avm_status avm_solver_options_init(avm_solver_options* options);
/* What C and C++ callers get: the sized form with the struct as they were compiled with. */
#define avm_solver_options_init(options) \
  avm_solver_options_init_sized((options), sizeof(avm_solver_options))

/* ---- solver -------------------------------------------------------------------------- */

/* A solver: landmark frames in capture order -> solved, filtered poses, plus a resampler
 * for render times. Opaque; created by avm_solver_create(). */
typedef struct avm_solver avm_solver;

/* Creates a solver. `options` NULL means the defaults; it is only read during the call.
 * On success *out_solver is a new handle owned by the caller (free it with
 * avm_solver_destroy()).
 * Failures (*out_solver is set to NULL whenever out_solver is not NULL):
 *   AVM_ERROR_INVALID_ARGUMENT: out_solver is NULL; options->struct_size below 8 or above
 *     4096 (the struct was not initialised with avm_solver_options_init()); a field out of
 *     its range (the message names it);
 *   AVM_ERROR_OUT_OF_MEMORY; AVM_ERROR_INTERNAL.
 * The message of the last failure is given by avm_last_create_error(). Thread-safe. */
AVATARMAP_C_API avm_status avm_solver_create(const avm_solver_options* options,
                                             avm_solver** out_solver);

/* Message of the calling thread's last failed avm_solver_create() (or avm_solve_file()
 * option check), naming the field and its allowed range; "" when the last such call
 * succeeded or none was made. The string belongs to the library and is valid until the
 * calling thread's next avm_solver_create() or avm_solve_file(). Thread-safe (per thread). */
AVATARMAP_C_API const char* avm_last_create_error(void);

/* Frees a solver and everything it owns, including its last_error string. NULL does
 * nothing. The handle must not be in use by another thread. */
AVATARMAP_C_API void avm_solver_destroy(avm_solver* solver);

/* Forgets every frame pushed so far (solver state, filters, resampler history); options are
 * kept. Returns AVM_ERROR_INVALID_ARGUMENT when `solver` is NULL. */
AVATARMAP_C_API avm_status avm_solver_reset(avm_solver* solver);

/* Solves one frame, filters the result (if enabled in the options) and adds it to the
 * resampler's history. Frames must come in capture order; a frame whose t is earlier than the
 * previous frame's resets the solver first (as avm_solver_reset()). The frame and its arrays
 * are only read during the call. Allocates nothing.
 * Failures (the solver's state is unchanged):
 *   AVM_ERROR_INVALID_ARGUMENT: solver or frame NULL, t not finite, face not NULL with
 *     face_count other than 468 or 478;
 *   AVM_ERROR_INTERNAL. avm_solver_last_error() says which. */
AVATARMAP_C_API avm_status avm_solver_push(avm_solver* solver, const avm_frame* frame);

/* Copies the latest solved and filtered pose into *out_pose (owned by the caller). Before
 * the first push (or after a reset) it is the rest pose (T-pose, hips 0.95 m above the
 * floor, t = 0).
 * Failures: AVM_ERROR_INVALID_ARGUMENT when solver or out_pose is NULL. */
AVATARMAP_C_API avm_status avm_solver_get_pose(const avm_solver* solver, avm_pose* out_pose);

/* Writes the pose at render time t (seconds, on the frames' clock) into *out_pose. The solver
 * keeps the last 4 pushed (filtered) poses: between two of them the pose is interpolated
 * (rotations by shortest-arc slerp, position, expressions and blendshapes linearly, confidence the
 * minimum); before the oldest kept it is the oldest; past the newest it is extrapolated at
 * constant velocity for at most max_extrapolation_seconds, then held. Before the first push
 * (or after a reset) it is the rest pose. out_pose->t = t. Allocates nothing; does not
 * change what later calls return.
 * Failures: AVM_ERROR_INVALID_ARGUMENT when solver or out_pose is NULL or t is not finite;
 *   AVM_ERROR_INTERNAL. */
AVATARMAP_C_API avm_status avm_solver_sample(avm_solver* solver, double t, avm_pose* out_pose);

/* Message of the last failed call on `solver` ("" after a successful call, or when `solver`
 * is NULL). The string is owned by the solver and valid until the next call on it or its
 * destruction. */
AVATARMAP_C_API const char* avm_solver_last_error(const avm_solver* solver);

/* ---- files --------------------------------------------------------------------------- */

/* Solves a whole *.landmarks.jsonl file into a *.pose.jsonl file (docs/file-formats.md): every
 * frame is solved as by avm_solver_push() and smoothed as options->file_filter says (by default
 * offline: zero-lag smoothing and gap filling with a 1.5 s lookahead, memory bounded by
 * its window; AVM_FILE_FILTER_LIVE gives exactly avm_solver_push()'s filtering); no
 * resampling. The image size of the
 * landmark file's header is used when options give none. The output is written atomically:
 * a temporary file beside `out_pose` is renamed over it only when everything succeeded, so
 * on failure an existing `out_pose` is untouched. `options` NULL means the defaults.
 * When `err` is not NULL and err_size > 0, a NUL-terminated message (truncated to fit) is
 * written there: "" on success, else what failed and where ("FILE:LINE: ...").
 * Failures: AVM_ERROR_INVALID_ARGUMENT (a path NULL, bad options), AVM_ERROR_IO (cannot
 *   open, write or rename), AVM_ERROR_PARSE (a malformed line: the first one stops the
 *   run), AVM_ERROR_OUT_OF_MEMORY, AVM_ERROR_INTERNAL. Thread-safe (separate files). The
 * file is parsed ahead on a second thread of the call's own, as `avatarmap solve` does
 * (options->file_threads 1: all on the calling thread). */
AVATARMAP_C_API avm_status avm_solve_file(const char* in_landmarks, const char* out_pose,
                                          const avm_solver_options* options, char* err,
                                          size_t err_size);

/* ---- mapping tables ------------------------------------------------------------------ */

/* Rigs that declare no humanoid map (plain glTF/GLB: Mixamo, Unity, Unreal, Character
 * Creator, ...) are bound by mapping tables (docs/mappings.md): JSON files that list each
 * family's joint names. Wherever a function takes a `mapping` argument it means:
 *   NULL or "auto"  the humanoid map the avatar declares (VRM 0.x / 1.0), else the
 *                   best-matching table of the mappings folder (below);
 *   "NAME"          the table of the mappings folder whose "name" is NAME ("mixamo",
 *                   "unity_humanoid", "ue5_mannequin", "vrm1", ...);
 *   "PATH.json"     the table in that file (any name ending in ".json"); its per-bone
 *                   formulas, if any, apply.
 * The mappings folder is found as avm_find_resource(AVM_RESOURCE_MAPPINGS) says: the folder
 * given to avm_set_mappings_folder(), else $AVATARMAP_MAPPINGS when that is set and not empty,
 * else the installed tables (share/avatarmap/mappings beside this library), else the source
 * tree's mappings/; it is read (all of its *.json but schema.json) by each call that needs a
 * table of it. */

/* Sets the process-wide mappings folder, which takes precedence over $AVATARMAP_MAPPINGS and
 * the installed and source-tree tables.
 * The string is copied; NULL or "" forgets the folder. Calls that start afterwards use the
 * new folder; calls already running keep the one they read.
 * Failures: AVM_ERROR_OUT_OF_MEMORY (the previous folder is kept). The folder is not checked
 * here: a missing folder is reported by the call that needs it.
 * Thread-safe (may be called at any time from any thread). */
AVATARMAP_C_API avm_status avm_set_mappings_folder(const char* folder);

/* ---- shipped folders ------------------------------------------------------------------ */

/* The folders the library looks for (docs/architecture.md, "Resources"). */
typedef enum avm_resource {
  AVM_RESOURCE_MAPPINGS = 0,      /* the mapping tables */
  AVM_RESOURCE_MODELS = 1,        /* the converted ONNX models (the models cache's onnx/) */
  AVM_RESOURCE_VIEWER_PAGE = 2,   /* the browser viewer's page */
  AVM_RESOURCE_VIEWER_MODULES = 3 /* three.js and three-vrm for the viewer */
} avm_resource;

/* Finds one of the shipped folders in the one order the command-line tool and the Python
 * package use too: `explicit_folder` when not NULL or "" (for AVM_RESOURCE_MAPPINGS, NULL
 * means the folder given to avm_set_mappings_folder()); else the environment
 * ($AVATARMAP_MAPPINGS, $AVATARMAP_MODELS + "/onnx", $AVATARMAP_VIEWER_PAGE,
 * $AVATARMAP_VIEWER_MODULES) when set and not empty; else the installed folder beside this
 * library (LIBDIR/../share/avatarmap/...) when it exists; else the source tree the library was
 * built from when that folder exists. The first two are taken unchecked.
 * `kind` is an avm_resource. Writes the folder to out_folder (folder_size bytes) and the rule
 * that found it to out_rule (rule_size bytes: "argument", "environment AVATARMAP_MODELS" (the
 * variable's name), "installed", "source tree"); either may be NULL when its size is 0; both
 * are "" unless AVM_OK. `err` as avm_solve_file's.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (an unknown kind, or a buffer too small for the folder
 *   or the rule: nothing is truncated and err says the size needed), AVM_ERROR_IO (no rule
 *   found a folder: err lists every place looked at), AVM_ERROR_OUT_OF_MEMORY.
 * Thread-safe (reads the environment and the file system on each call). */
AVATARMAP_C_API avm_status avm_find_resource(int kind, const char* explicit_folder,
                                             char* out_folder, size_t folder_size, char* out_rule,
                                             size_t rule_size, char* err, size_t err_size);

/* ---- retargeting onto an avatar ------------------------------------------------------ */

/* A rig loaded from an avatar file (glTF/GLB, VRM 0.x, VRM 1.0) with its proxy-bone binding,
 * turning proxy poses into the rig's local joint rotations (rest-pose aware; docs/conventions.md).
 * Typed opaque handle; one thread at a time per handle; different handles are independent. */
typedef struct avm_retargeter avm_retargeter;

/* Loads `avatar_path` and binds its joints to the proxy bones as `mapping` says (see "mapping
 * tables" above; NULL = "auto"). Both strings are only read during the call. On success *out
 * is a new handle owned by the caller (free it with avm_retargeter_destroy()). On failure
 * *out is NULL (when out is not NULL) and avm_last_create_error() (thread-local, valid until
 * the next create on this thread) says why, naming the file (avatar or table) and, when a
 * table does not fit, the required bones the rig lacks.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (avatar_path or out NULL; `mapping` names no table of
 *     the mappings folder: the message lists the names),
 *   AVM_ERROR_IO (the avatar, the .json table or the mappings folder cannot be read, or no
 *     mappings folder is set when one is needed),
 *   AVM_ERROR_PARSE (not a valid avatar; a malformed table; the table, or with "auto" every
 *     table, lacks bones the rig needs; no hips bound),
 *   AVM_ERROR_OUT_OF_MEMORY, AVM_ERROR_INTERNAL.
 * Thread-safe (reads files only). */
AVATARMAP_C_API avm_status avm_retargeter_create(const char* avatar_path, const char* mapping,
                                                 avm_retargeter** out);

/* Options of a retargeter. Initialise with avm_retargeter_options_init(), then change fields
 * (struct_size as for avm_solver_options). Booleans are int32_t, 0 or non-zero. */
typedef struct avm_retargeter_options {
  uint32_t struct_size; /* sizeof(avm_retargeter_options) as the caller knows it */
  /* Foot locking (docs/foot-locking.md), kept by the handle across avm_retargeter_apply()
   * calls, which must then come in time order (a pose whose t is not later than the
   * previous one's starts a new clip: the anchors are forgotten): a foot whose
   * avm_pose.foot_contact rises
   * above 0 is anchored where it stands and held there by two-bone leg IK on the avatar's own
   * legs while the contact lasts. 1 (default); 0: off (and the three below with it). */
  int32_t foot_lock;
  int32_t foot_lock_align_foot;       /* turn a planted foot flat on the floor; 1 */
  int32_t foot_lock_lower_hips;       /* lower the hips when a leg cannot reach; 1 */
  int32_t foot_lock_keep_above_floor; /* heels and toes never below the floor; 1 */
} avm_retargeter_options;

/* Fills the first `size` bytes of *options with the defaults above and sets struct_size =
 * size, as avm_solver_options_init_sized() (size at least 8, at most 4096, a multiple of 4).
 * Thread-safe. */
AVATARMAP_C_API avm_status avm_retargeter_options_init_sized(avm_retargeter_options* options,
                                                             size_t size);
/* The function, for binaries built before the macro below. */
AVATARMAP_C_API avm_status avm_retargeter_options_init(avm_retargeter_options* options);
#define avm_retargeter_options_init(options) \
  avm_retargeter_options_init_sized((options), sizeof(avm_retargeter_options))

/* avm_retargeter_create() with options (NULL: the defaults, which avm_retargeter_create()
 * uses). A leg the avatar cannot lock (no lower leg, foot or toes joint) is not an error: the
 * binding description (avm_retargeter_binding_description()) ends with a sentence saying
 * foot locking is off for it. Failures as avm_retargeter_create(), and
 * AVM_ERROR_INVALID_ARGUMENT for a struct_size below 8 or above 4096. */
AVATARMAP_C_API avm_status avm_retargeter_create_with_options(const char* avatar_path,
                                                              const char* mapping,
                                                              const avm_retargeter_options* options,
                                                              avm_retargeter** out);

/* Forgets the foot-lock anchors (a new clip, a jump in time). NULL is a no-op. */
AVATARMAP_C_API void avm_retargeter_reset(avm_retargeter* retargeter);

/* Destroys a retargeter and the strings it owns; NULL is a no-op. The handle must not be in
 * use by another thread. */
AVATARMAP_C_API void avm_retargeter_destroy(avm_retargeter* retargeter);

/* Number of joints of the rig (0 when retargeter is NULL). Joints are in parent-first order. */
AVATARMAP_C_API int avm_retargeter_joint_count(const avm_retargeter* retargeter);

/* Name of joint `joint` as in the file (owned by the handle, valid for its lifetime), or NULL
 * when out of range. */
AVATARMAP_C_API const char* avm_retargeter_joint_name(const avm_retargeter* retargeter, int joint);

/* Parent joint index (-1 for a root or out of range). */
AVATARMAP_C_API int avm_retargeter_joint_parent(const avm_retargeter* retargeter, int joint);

/* Joint driven by proxy bone `bone` (an avm_bone), or -1 when the rig has none. */
AVATARMAP_C_API int avm_retargeter_bone_joint(const avm_retargeter* retargeter, int bone);

/* How the joints were bound, for the user: e.g. "VRM 1.0 humanoid declared by the file (53
 * bones)", "detected mixamo: matched 52/52 bones (prefix 'mixamorig:')" or "table NAME
 * (PATH.json): matched ...". Owned by the handle, valid for its lifetime; "" when retargeter
 * is NULL. Cannot fail; may be called from several threads at once. */
AVATARMAP_C_API const char* avm_retargeter_binding_description(const avm_retargeter* retargeter);

/* Applies `pose` and writes every joint's local rotation {x, y, z, w} to out_rotations
 * (4 * joint_count floats, caller-owned) and the hips joint's local translation (in its
 * parent's units) to out_hips_translation (3 floats; may be NULL). Allocation-free.
 * Non-finite (or zero) rotations are taken as identity, non-finite positions as 0.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (NULL arguments), AVM_ERROR_INTERNAL. */
AVATARMAP_C_API avm_status avm_retargeter_apply(avm_retargeter* retargeter, const avm_pose* pose,
                                                float* out_rotations, float* out_hips_translation);

/* Message of the last failed call on `retargeter` ("" when none), owned by the handle. */
AVATARMAP_C_API const char* avm_retargeter_last_error(const avm_retargeter* retargeter);

/* ---- clips: writing animation files -------------------------------------------------- */

/* A clip: proxy poses collected in time order (e.g. from avm_solver_sample() at a fixed
 * rate) and written as an animation file. Typed opaque handle (about 1.2 kB per frame); one
 * thread at a time per handle; different handles are independent. */
typedef struct avm_clip avm_clip;

/* Creates an empty clip. On success *out is a new handle owned by the caller (free it with
 * avm_clip_destroy()); on failure *out is NULL (when out is not NULL) and
 * avm_last_create_error() says why.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (out NULL), AVM_ERROR_OUT_OF_MEMORY. Thread-safe. */
AVATARMAP_C_API avm_status avm_clip_create(avm_clip** out);

/* Frees a clip and its frames; NULL does nothing. The handle must not be in use by another
 * thread. */
AVATARMAP_C_API void avm_clip_destroy(avm_clip* clip);

/* Appends a copy of `pose` (only read during the call). pose->t must be finite and greater
 * than the previous frame's. Non-finite values are taken as missing: a rotation with a
 * non-finite component (or of zero length) becomes the previous frame's (identity for the
 * first frame) with confidence 0, a non-finite hips position the previous one (0, 0.95, 0 for
 * the first), a non-finite expression or blendshape weight the previous one (0); rotations
 * are normalised, weights and confidences clamped to [0, 1].
 * Failures (the clip is unchanged): AVM_ERROR_INVALID_ARGUMENT (clip or pose NULL, t not
 *   finite or not after the previous frame's), AVM_ERROR_OUT_OF_MEMORY.
 *   avm_clip_last_error() says which. */
AVATARMAP_C_API avm_status avm_clip_add(avm_clip* clip, const avm_pose* pose);

/* Number of frames added so far (0 when clip is NULL). */
AVATARMAP_C_API int avm_clip_frame_count(const avm_clip* clip);

/* Writes the clip to `path`, the format chosen by its extension (case-insensitive):
 *   .vrma        VRM Animation 1.0 (a GLB) on the VRM humanoid; avatar_path is ignored;
 *   .bvh         BVH, centimetres, ZXY: with avatar_path NULL, of the proxy skeleton (55 VRM
 *                bones); else of the avatar's own rig (its joints, names and proportions;
 *                the hips' subtree), the clip retargeted onto it as for .glb;
 *   .pose.jsonl  avatarmap proxy poses (docs/file-formats.md); avatar_path is ignored;
 *   .glb         the avatar at avatar_path (required; .vrm, .glb or .gltf) with the clip as a
 *                glTF animation of its joints, bound as `mapping` says (see "mapping tables";
 *                NULL = "auto"); meshes, materials and extensions are kept.
 * `fps` > 0 (at most AVM_MAX_FPS) resamples the clip at that rate from its first frame (slerp on
 * the shortest arc, linear for positions and weights); 0 keeps the frames' own times (.vrma keys at
 * those times, the proxy .bvh plays them at their mean spacing, .pose.jsonl writes them as they
 * are), except with an avatar (.glb, .bvh of the rig), which needs a fixed rate and is resampled at
 * 30 fps. Times are written from 0 (the first frame's t is subtracted), except in .pose.jsonl at
 * fps 0. The file is written atomically (a temporary file beside `path` renamed over it), so on
 * failure an existing file at `path` is untouched. The clip is not changed: it may be written
 * again, e.g. in another format.
 * When `err` is not NULL and err_size > 0, a NUL-terminated message (truncated to fit) is
 * written there: "" on success, else what failed, naming the file; avm_clip_last_error() gives
 * the same message.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (clip or path NULL, the clip has no frames, fps
 *     negative, above AVM_MAX_FPS or not finite, an unknown extension, .glb without avatar_path,
 *     `mapping` names no table, the clip spans more than 24 hours (86400 s from its first
 *     frame to its last) or would be more than 4194304 frames at the rate written),
 *   AVM_ERROR_IO (cannot write `path`; the avatar, table or mappings folder cannot be read,
 *     or no mappings folder is set when one is needed),
 *   AVM_ERROR_PARSE (the avatar or a table is malformed, or does not fit the avatar; no hips
 *     bound),
 *   AVM_ERROR_OUT_OF_MEMORY, AVM_ERROR_INTERNAL.
 * One thread at a time per clip; writing different files from different clips at once is
 * safe. */
AVATARMAP_C_API avm_status avm_clip_write(avm_clip* clip, const char* path, double fps,
                                          const char* avatar_path, const char* mapping, char* err,
                                          size_t err_size);

/* Message of the last failed call on `clip` ("" after a successful call, or when clip is
 * NULL). Owned by the clip, valid until the next call on it or its destruction. */
AVATARMAP_C_API const char* avm_clip_last_error(const avm_clip* clip);

/* ---- capture: images -> landmarks -> poses ------------------------------------------- */

/* Pixel layouts of avm_image: 8 bits per channel, rows top to bottom. */
typedef enum avm_pixel_format {
  AVM_PIXEL_RGB8 = 0,
  AVM_PIXEL_BGR8 = 1,
  AVM_PIXEL_RGBA8 = 2,
  AVM_PIXEL_BGRA8 = 3
} avm_pixel_format;

/* An image owned by the caller, only read during the call that receives it. */
typedef struct avm_image {
  const uint8_t* data;  /* the first row's first pixel */
  int32_t width;        /* pixels, 1 .. 16384 */
  int32_t height;       /* pixels, 1 .. 16384 */
  int32_t stride_bytes; /* bytes from one row to the next, >= width x bytes per pixel */
  int32_t format;       /* an avm_pixel_format */
} avm_image;

/* Options of the estimator (MediaPipe's models on ONNX Runtime, CPU). Initialise with
 * avm_estimator_options_init(), then change fields (struct_size as for avm_solver_options).
 * Booleans are int32_t, 0 or non-zero. */
typedef struct avm_estimator_options {
  uint32_t struct_size;          /* sizeof(avm_estimator_options) as the caller knows it */
  const char* models_dir;        /* the converted models (scripts/prepare_capture.sh makes them);
                                    NULL or "": avm_find_resource(AVM_RESOURCE_MODELS) (first
                                    $AVATARMAP_MODELS/onnx). Read during create only. */
  int32_t model_complexity;      /* body landmark model: 0 lite, 1 full (default), 2 heavy */
  int32_t hands;                 /* estimate both hands (default 1) */
  int32_t face;                  /* estimate the face mesh (default 1) */
  int32_t hand_model_complexity; /* hand landmark model: 0 lite, 1 full (default) */
  int32_t threads;               /* ONNX Runtime threads, 1 .. AVM_MAX_MODEL_THREADS (default 2) */
  int32_t mirrored;              /* the images are mirrored (a selfie preview); default 0 */
  int32_t static_images;         /* detect on every image (unrelated stills); default 0 */
  /* -- added after static_images (a struct_size that ends before it gets 1; on 64-bit
   *    targets it takes what was the struct's tail padding, sizeof unchanged: a caller built
   *    before it gets 1 there from avm_estimator_options_init()) -- */
  /* How many people to follow, 1 .. AVM_MAX_PEOPLE (default 1, the single-person capture;
   * docs/capture-people.md). avm_capture_file() with more than 1 writes a version-2 landmark
   * file (one line per person in view and frame, each with its "person" id); the estimator
   * and live handles follow that many: avm_estimator_process_people() and avm_live_people() /
   * avm_live_sample_person() give every person, the single-person calls the lowest id. */
  int32_t max_people;
} avm_estimator_options;

/* Fills the first `size` bytes of *options with the defaults above and sets struct_size =
 * size, as avm_solver_options_init_sized() (size at least 16, at most 4096, a multiple of 4).
 * AVM_ERROR_INVALID_ARGUMENT when options is NULL or size is out of range. */
AVATARMAP_C_API avm_status avm_estimator_options_init_sized(avm_estimator_options* options,
                                                            size_t size);
/* Fills *options with the defaults above (sizeof(avm_estimator_options) of this library).
 * AVM_ERROR_INVALID_ARGUMENT when options is NULL. C and C++ callers get the macro below: the
 * sized form with the struct as they were compiled with. */
AVATARMAP_C_API avm_status avm_estimator_options_init(avm_estimator_options* options);
#define avm_estimator_options_init(options) \
  avm_estimator_options_init_sized((options), sizeof(avm_estimator_options))

/* An estimator: images in capture order -> landmarks -> solved, live-filtered poses (the
 * same steps as `avatarmap live`). Opaque; created by avm_estimator_create(). */
typedef struct avm_estimator avm_estimator;

/* Creates an estimator: loads the models (a few hundred milliseconds). `options` NULL = the
 * defaults; `solver_options` NULL = the solver's defaults (its image size 0 = each image's;
 * its filter fields set the live filter; file_* fields are not used). Both are only read
 * during the call. On success *out is a new handle owned by the caller (free it with
 * avm_estimator_destroy()).
 * Failures (*out is set to NULL whenever out is not NULL):
 *   AVM_ERROR_INVALID_ARGUMENT: out NULL, a field out of range, no models folder given and
 *     none found (avm_find_resource(AVM_RESOURCE_MODELS));
 *   AVM_ERROR_IO: the models are missing or unreadable (the message names the folder);
 *   AVM_ERROR_UNSUPPORTED: this library was built without the ONNX Runtime backend;
 *   AVM_ERROR_OUT_OF_MEMORY; AVM_ERROR_INTERNAL. avm_last_create_error() says which.
 * Thread-safe. */
AVATARMAP_C_API avm_status avm_estimator_create(const avm_estimator_options* options,
                                                const avm_solver_options* solver_options,
                                                avm_estimator** out);

/* Frees an estimator. NULL does nothing. The handle must not be in use by another thread. */
AVATARMAP_C_API void avm_estimator_destroy(avm_estimator* estimator);

/* Estimates the landmarks of one image (capture time t, seconds, increasing) and solves and
 * filters them. Either output may be NULL. *out_frame's pointers then point into the
 * estimator's own storage (NULL for parts not seen), valid until the next call on it or its
 * destruction; *out_pose is copied. A frame with no person is not an error (its parts are
 * NULL; the pose holds and eases what was lost). Allocates nothing outside ONNX Runtime.
 * One thread at a time per estimator.
 * Failures (outputs unchanged): AVM_ERROR_INVALID_ARGUMENT: estimator or image NULL, no
 *   pixels, a size outside 1 .. 16384, an unknown format, a stride below width x bytes per
 *   pixel, t not finite; AVM_ERROR_INTERNAL (the estimator failed). avm_estimator_last_error()
 *   says which. */
AVATARMAP_C_API avm_status avm_estimator_process(avm_estimator* estimator, const avm_image* image,
                                                 double t, avm_frame* out_frame,
                                                 avm_pose* out_pose);

/* One person of an image (several people: docs/capture-people.md). */
typedef struct avm_person {
  int32_t id;      /* the person's id: kept while the person is followed (through crossings and
                      losses of up to 1 s), never given to anyone else */
  int32_t slot;    /* the person's place, 0 .. max_people-1: its own for as long as its id lives
                      (a new id takes the lowest free slot; a slot is freed 1 s after its person
                      was last seen) */
  avm_frame frame; /* its landmarks; pointers into the estimator's storage, valid until the
                      next call on it */
  avm_pose pose;   /* its solved, live-filtered pose (each person has a filter of its own) */
} avm_person;

/* Several people (avm_estimator_options.max_people > 1): estimates every person of one image
 * (capture time t, seconds, increasing), each solved and filtered on its own, into
 * out_people[0 .. min(count, capacity)) ascending by id; *out_count = the people in view (0
 * when nobody is; may exceed capacity: the rest are not written). With max_people 1: the one
 * person of avm_estimator_process() (id 0, slot 0), or none when no body is seen. Do not mix
 * with avm_estimator_process() on one handle (each keeps the people's filters going).
 * Allocates nothing outside ONNX Runtime. One thread at a time per estimator.
 * Failures (outputs unchanged): those of avm_estimator_process(); AVM_ERROR_INVALID_ARGUMENT
 *   also when out_count is NULL, capacity is negative, or out_people is NULL with capacity > 0. */
AVATARMAP_C_API avm_status avm_estimator_process_people(avm_estimator* estimator,
                                                        const avm_image* image, double t,
                                                        avm_person* out_people, int32_t capacity,
                                                        int32_t* out_count);

/* Message of the last failed call on `estimator` ("" after a success or for NULL); owned by
 * the estimator, valid until the next call on it or its destruction. */
AVATARMAP_C_API const char* avm_estimator_last_error(const avm_estimator* estimator);

/* ---- live: a camera thread pushes, a render thread polls ------------------------------ */

/* A live capture: the caller's camera thread pushes images (copied, never waiting for
 * processing); a worker thread of the handle processes the newest one as avm_estimator does
 * (one pushed while it is busy replaces the waiting one: dropped and counted, so latency
 * stays one frame's processing time); any thread asks for the pose at any time. Opaque. */
typedef struct avm_live avm_live;

/* Counters and latency of a live handle. */
typedef struct avm_live_stats {
  int64_t pushed;        /* images pushed */
  int64_t processed;     /* images processed */
  int64_t dropped;       /* images replaced before the worker took them */
  int64_t failed;        /* images the estimator failed on (avm_live_last_error) */
  double latency_p50_ms; /* push -> pose ready, over the last 4096 processed images */
  double latency_p95_ms;
  double latency_max_ms;
  double newest_t; /* capture time of the newest processed pose; 0 before the first */
} avm_live_stats;

/* Creates a live handle and starts its worker thread; options as avm_estimator_create() (the
 * solver options' max_extrapolation_seconds bounds avm_live_sample()'s extrapolation).
 * Failures and messages as avm_estimator_create(). Thread-safe. */
AVATARMAP_C_API avm_status avm_live_create(const avm_estimator_options* options,
                                           const avm_solver_options* solver_options,
                                           avm_live** out);

/* Stops the worker (waits for the image in process, if any) and frees the handle. NULL does
 * nothing. Any thread: calls on the handle already in flight on other threads are waited for,
 * and a call that starts once destroy has begun fails with AVM_ERROR_INVALID_ARGUMENT (the
 * handle is looked up, not dereferenced; avm_live_last_error says it was destroyed) — until
 * a new live handle happens to get the same address, so do not rely on it after destroy has
 * returned. Destroying twice is a no-op. */
AVATARMAP_C_API void avm_live_destroy(avm_live* live);

/* Camera thread: copies `image` (capture time t, seconds, increasing) for the worker and
 * returns at once. Allocates only when an image larger than any before arrives. Pushes from
 * several threads are serialised (each waits for the one in progress); pushes run
 * concurrently with the calls below.
 * Failures (nothing queued): AVM_ERROR_INVALID_ARGUMENT for the image checks of
 * avm_estimator_process() or t not finite. */
AVATARMAP_C_API avm_status avm_live_push(avm_live* live, const avm_image* image, double t);

/* Any thread, any time: the pose at capture time t (slerp between processed frames, a short
 * extrapolation past the newest, then held) into *out_pose (out_pose->t = t). To follow a
 * camera, pass the newest capture time you pushed (or that minus a frame for pure
 * interpolation). Before the first processed image: AVM_ERROR_END_OF_FILE and the rest pose.
 * Allocates nothing.
 * Failures: AVM_ERROR_INVALID_ARGUMENT when live or out_pose is NULL or t is not finite. */
AVATARMAP_C_API avm_status avm_live_sample(const avm_live* live, double t, avm_pose* out_pose);

/* Any thread, any time: the newest processed pose. Before the first: AVM_ERROR_END_OF_FILE
 * and the rest pose. Failures: AVM_ERROR_INVALID_ARGUMENT when live or out_pose is NULL. */
AVATARMAP_C_API avm_status avm_live_latest(const avm_live* live, avm_pose* out_pose);

/* A person a live handle holds (several people). */
typedef struct avm_live_person {
  int32_t id;    /* as avm_person.id */
  int32_t slot;  /* as avm_person.slot */
  double seen_t; /* capture time the person was last seen */
} avm_live_person;

/* Any thread, any time: the people held now (in view, or unseen for under 1 s), ascending by
 * id, into out_people[0 .. min(count, capacity)); *out_count = how many (may exceed capacity).
 * With max_people 1: one entry (id 0, slot 0) once an image was processed.
 * Failures: AVM_ERROR_INVALID_ARGUMENT when live or out_count is NULL, capacity is negative or
 * out_people is NULL with capacity > 0. */
AVATARMAP_C_API avm_status avm_live_people(const avm_live* live, avm_live_person* out_people,
                                           int32_t capacity, int32_t* out_count);

/* Any thread, any time: as avm_live_sample(), for the person `id` (avm_live_people()). A person
 * not held (never seen, or gone for over 1 s): AVM_ERROR_END_OF_FILE and the rest pose.
 * Failures: AVM_ERROR_INVALID_ARGUMENT when live or out_pose is NULL or t is not finite. */
AVATARMAP_C_API avm_status avm_live_sample_person(const avm_live* live, int32_t id, double t,
                                                  avm_pose* out_pose);

/* Any thread: the counters and latency so far. AVM_ERROR_INVALID_ARGUMENT when an argument
 * is NULL (or the handle was destroyed, as for every avm_live_* call). */
AVATARMAP_C_API avm_status avm_live_get_stats(const avm_live* live, avm_live_stats* out_stats);

/* Any thread: the message of the last image the worker failed on, else of the last failed
 * call on the handle ("" when none, or for NULL). Copied into `buffer` (truncated, always
 * NUL-terminated); returns `buffer`. */
AVATARMAP_C_API const char* avm_live_last_error(const avm_live* live, char* buffer,
                                                size_t buffer_size);

/* ---- arrays of frames: whole-file calls from array languages --------------------------- */

/* Frames as arrays (structure of arrays), e.g. NumPy arrays handed over by pointer. Each
 * points array holds count x N x 5 floats, (x, y, z, visibility, presence) per point as in
 * avm_landmark, frame after frame: N = AVM_POSE_LANDMARK_COUNT (pose, pose_world),
 * AVM_HAND_LANDMARK_COUNT (hands), AVM_FACE_IRIS_LANDMARK_COUNT (face; a 468-point face has
 * rows 468..477 NaN: its row 468's x is NaN). A part is not seen in frame i when its first
 * point's x is NaN (readers fill unseen parts with NaN). Any pointer but t may be NULL: that
 * part is never seen. The caller owns every array. */
typedef struct avm_frame_block {
  uint32_t struct_size;    /* sizeof(avm_frame_block) as the caller knows it */
  int64_t count;           /* frames (capacity for readers), >= 0 */
  double* t;               /* count capture times, seconds */
  float* pose;             /* count x 33 x 5 */
  float* pose_world;       /* count x 33 x 5 */
  float* left_hand;        /* count x 21 x 5 */
  float* left_hand_world;  /* count x 21 x 5 */
  float* right_hand;       /* count x 21 x 5 */
  float* right_hand_world; /* count x 21 x 5 */
  float* face;             /* count x 478 x 5 */
  /* -- added after face (a caller whose struct_size ends before it has no person column:
   *    readers write none, avm_solve_frames takes every row as one person) -- */
  /* count person ids, one per row (NULL: not wanted). avm_landmark_reader_read writes each
   * line's "person" (docs/file-formats.md, version 2: a frame of several people is several
   * rows with the same t, ascending by id); every row of a version-1 file is person 0 (the
   * id avm_solver_options.person picks it by). Ids are 0 .. 999999; -1 is never written.
   * avm_solve_frames solves one person: it refuses a column holding more than one distinct
   * value (solve each person's rows on their own, or use avm_solve_file with
   * avm_solver_options.person). */
  int32_t* person;
} avm_frame_block;

/* Reader of a *.landmarks.jsonl file (docs/file-formats.md), a block of frames at a time.
 * Typed opaque handle; one thread at a time per handle. */
typedef struct avm_landmark_reader avm_landmark_reader;

/* Opens `path` and reads its header line, if any. On success *out is a new handle owned by
 * the caller (free it with avm_landmark_reader_destroy()); on failure *out is NULL (when out
 * is not NULL) and avm_last_create_error() says why, naming the file.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (path or out NULL), AVM_ERROR_IO (cannot open),
 *   AVM_ERROR_PARSE (a bad header line), AVM_ERROR_OUT_OF_MEMORY. Thread-safe. */
AVATARMAP_C_API avm_status avm_landmark_reader_open(const char* path, avm_landmark_reader** out);

/* The header's values into each non-NULL output: the image size in pixels (0 when the file
 * gives none) and the frame rate (0 when unknown).
 * Failures: AVM_ERROR_INVALID_ARGUMENT when r is NULL. */
AVATARMAP_C_API avm_status avm_landmark_reader_header(const avm_landmark_reader* r,
                                                      int32_t* image_width, int32_t* image_height,
                                                      double* fps);

/* Reads up to block->count lines into rows 0, 1, ... of the block's arrays (NULL arrays are
 * skipped; parts a line lacks, and rows 468..477 of a 468-point face, are filled with NaN).
 * A line is a row: in a file of several people (version 2) one frame's people are
 * consecutive rows with the same t, told apart by block->person (0 for every row of a
 * version-1 file). *out_read = the number of rows read; 0 with AVM_OK at the end of the
 * file. Allocates nothing per frame.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (r, block, block->t or out_read NULL, struct_size
 *   below offsetof(avm_frame_block, person), count negative); AVM_ERROR_PARSE: a malformed line,
 *   "FILE:LINE: ..." in avm_landmark_reader_last_error(); *out_read then counts the good
 *   frames read before it, and the next call goes on after the bad line;
 *   AVM_ERROR_IO (a read error), AVM_ERROR_INTERNAL. */
AVATARMAP_C_API avm_status avm_landmark_reader_read(avm_landmark_reader* r,
                                                    const avm_frame_block* block,
                                                    int64_t* out_read);

/* Message of the last failed call on `r` ("" after a successful call, or for NULL); owned by
 * the handle, valid until the next call on it or its destruction. */
AVATARMAP_C_API const char* avm_landmark_reader_last_error(const avm_landmark_reader* r);

/* Closes the file and frees the handle; NULL does nothing. */
AVATARMAP_C_API void avm_landmark_reader_destroy(avm_landmark_reader* r);

/* Solves frames->count frames held in memory exactly as avm_solve_file() solves a file (the
 * same library job: options->file_filter, offline by default; one pose per frame, in the
 * block's order, no resampling) into out_poses[0 .. count) (caller-owned). The image size is
 * options->image_width/height (0: unknown, square pixels assumed). The block's arrays are
 * only read during the call. Allocates nothing per frame (the offline filter's window once
 * per call). `options` NULL means the defaults. err as avm_solve_file().
 * The block is one person: a person column (frames->person) holding more than one distinct
 * id is refused (solve each person's rows on their own, or a file with avm_solve_file() and
 * avm_solver_options.person); options->person is not used.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (frames or out_poses NULL with count > 0, frames->t
 *   NULL, struct_size below offsetof(avm_frame_block, person), count negative, a time not
 *   finite, several person ids, bad options: the message names the frame or field),
 *   AVM_ERROR_OUT_OF_MEMORY,
 *   AVM_ERROR_INTERNAL. Thread-safe (separate outputs). */
AVATARMAP_C_API avm_status avm_solve_frames(const avm_frame_block* frames,
                                            const avm_solver_options* options, avm_pose* out_poses,
                                            char* err, size_t err_size);

/* Solves a whole *.landmarks.jsonl file as avm_solve_file() does (the same job, options and
 * poses, the file parsed ahead on a second thread) but keeps the poses, with their per-bone
 * confidence, in a new clip instead of writing them: read them with avm_clip_get_poses(), or
 * write them with avm_clip_write(). About 1.2 kB of memory per frame. On success *out is a new
 * handle owned by the caller (free it with avm_clip_destroy()); on failure *out is NULL (when
 * out is not NULL). err and failures as avm_solve_file(). Thread-safe (separate files). */
AVATARMAP_C_API avm_status avm_solve_file_to_clip(const char* in_landmarks,
                                                  const avm_solver_options* options, avm_clip** out,
                                                  char* err, size_t err_size);

/* ---- clips: more than one pose at a time, and reading pose files ----------------------- */

/* Reads a *.pose.jsonl file (docs/file-formats.md) or a .vrma into a new clip with the
 * reader avm_convert_file() uses (avm_motion_input_kind()'s rule): the frames put in time
 * order by its one rule (sorted stably; frames at equal times are kept, the later one winning
 * when the clip is resampled) and the header's nominal rate (a .pose.jsonl written from the
 * clip at fps 0 keeps it; 0 for a .vrma). On success *out is a new handle owned by the caller
 * (free it with avm_clip_destroy()); on failure *out is NULL (when out is not NULL). err as
 * avm_clip_write().
 * Failures: AVM_ERROR_INVALID_ARGUMENT (path or out NULL; a landmark file (solve it with
 *   avm_solve_file_to_clip()) or no motion file), AVM_ERROR_IO (cannot open),
 *   AVM_ERROR_PARSE (a malformed line: "FILE:LINE: ...", or .vrma), AVM_ERROR_OUT_OF_MEMORY.
 *   Thread-safe. */
AVATARMAP_C_API avm_status avm_clip_read(const char* path, avm_clip** out, char* err,
                                         size_t err_size);

/* Copies frames [first, first + count) into out[0 .. count) (caller-owned poses; the frames
 * as the clip holds them: sanitised as avm_clip_add() says). Allocates nothing.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (clip NULL, out NULL with count > 0, first or count
 *   negative, the range past the clip's frames). */
AVATARMAP_C_API avm_status avm_clip_get_poses(const avm_clip* clip, int64_t first, int64_t count,
                                              avm_pose* out);

/* Appends count poses as avm_clip_add() would each, all or nothing: on failure the clip is
 * unchanged and avm_clip_last_error() names the first bad pose.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (clip NULL, poses NULL with count > 0, count negative,
 *   a t not finite or not after the previous one's), AVM_ERROR_OUT_OF_MEMORY. */
AVATARMAP_C_API avm_status avm_clip_add_poses(avm_clip* clip, const avm_pose* poses, int64_t count);

/* ---- convert: a motion file into an animation file ------------------------------------- */

/* The kinds of motion file avm_convert_file() reads. */
typedef enum avm_motion_input {
  AVM_MOTION_INPUT_NONE = 0,      /* none of these: avm_convert_file() refuses it */
  AVM_MOTION_INPUT_LANDMARKS = 1, /* *.landmarks.jsonl: solved first */
  AVM_MOTION_INPUT_POSES = 2,     /* *.pose.jsonl */
  AVM_MOTION_INPUT_VRMA = 3,      /* *.vrma (VRM Animation) */
  AVM_MOTION_INPUT_BVH = 4        /* *.bvh: read on its own skeleton (docs/convert.md) */
} avm_motion_input;

/* The kind of motion file at `path` (an avm_motion_input), by the library's one rule (the CLI's
 * `convert` and the Python package use it too): the name's extension in any case
 * (.landmarks.jsonl, .pose.jsonl, .vrma); else "-" is landmarks; else a regular file's first
 * bytes ("glTF": .vrma; a JSON header whose "format" is "avatarmap.pose" or
 * "avatarmap.landmarks"); else a name ending in .jsonl is landmarks; else NONE (NULL too).
 * *out_stem_length (may be NULL) gets the length of `path` without the extension that decided
 * (without its last extension when the content did; 0 for NONE). Reads at most the first
 * 256 bytes of a regular file, never of a FIFO or device. Thread-safe; cannot fail. */
AVATARMAP_C_API int avm_motion_input_kind(const char* path, size_t* out_stem_length);

/* Called with each warning of avm_convert_file() (one sentence, no "warning:" prefix; the
 * string is valid during the call only), on the calling thread. */
typedef void (*avm_warning_fn)(void* user, const char* message);

/* Options of avm_convert_file(). Initialise with avm_convert_options_init(), then change
 * fields (struct_size as for avm_solver_options). */
typedef struct avm_convert_options {
  uint32_t struct_size; /* sizeof(avm_convert_options) as the caller knows it */
  double fps;           /* 0 (the default): the frames' own times (avatar outputs: 30 fps);
                           > 0: resampled at that rate, at most AVM_MAX_FPS (as avm_clip_write) */
  const char* avatar;   /* the avatar file (.vrm, .glb, .gltf): needed by .glb, turns .bvh into
                           the avatar's rig, unused (not loaded) by .vrma and .pose.jsonl;
                           NULL (default): none */
  const char* mapping;  /* how the avatar is bound ("mapping tables" above); NULL = "auto" */
  int32_t keep_feet_on_ground; /* keep the avatar's lowest foot on the floor; 0 */
  int32_t root_motion;         /* move the hips as captured (0: keep them at rest); 1 */
  /* How a landmark input is solved; NULL (default) = avm_solver_options_init()'s defaults.
   * Must be NULL for other inputs (AVM_ERROR_INVALID_ARGUMENT). Read during the call only. */
  const avm_solver_options* solver;
  avm_warning_fn warning; /* NULL (default): warnings are only counted in the summary */
  void* user;             /* passed to `warning` */
  /* -- added in 0.1.0 after user (a caller whose struct_size ends before it gets the
   *    default). -- */
  int32_t foot_lock; /* keep planted feet (the poses' foot_contact) planted on the output,
                        lower the hips when a leg cannot reach, keep heels and toes above the
                        floor (docs/foot-locking.md); 0: off; 1 (default) */
} avm_convert_options;

/* Fills the first `size` bytes of `options` with the defaults above and sets struct_size =
 * size, as avm_solver_options_init_sized() (size at least 16, at most 4096, a multiple of 4).
 * Thread-safe. */
AVATARMAP_C_API avm_status avm_convert_options_init_sized(avm_convert_options* options,
                                                          size_t size);
/* The function, for binaries built before the macro below. */
AVATARMAP_C_API avm_status avm_convert_options_init(avm_convert_options* options);
#define avm_convert_options_init(options) \
  avm_convert_options_init_sized((options), sizeof(avm_convert_options))

/* What avm_convert_file() did (filled as far as it got when it fails). Set struct_size =
 * sizeof(avm_convert_summary) before the call (a smaller one is refused). */
typedef struct avm_convert_summary {
  uint32_t struct_size;
  int32_t input_kind;          /* an avm_motion_input */
  int64_t frames_read;         /* poses read (or solved) from the input, before resampling */
  int64_t frames_out_of_order; /* frames earlier than the one before them (sorted; warned) */
  int64_t frames_written;
  double fps;     /* the rate written; 0: the frames' own times */
  double seconds; /* wall-clock time of the call */
} avm_convert_summary;

/* `avatarmap convert INPUT -o OUTPUT` as a library call (the same library job: the same input
 * and options give the same bytes): reads INPUT by avm_motion_input_kind()'s rule (landmarks
 * solved as avm_solve_file_to_clip() solves them with options->solver), puts its frames in
 * time order (stably: sorted, with one warning that counts the frames that were out of order;
 * every input, every output), binds the avatar when the output uses one (before reading: a bad
 * avatar fails first) and writes OUTPUT as avm_clip_write() would (its formats, resampling and
 * limits), atomically: on failure an existing file is untouched. `options` NULL means the
 * defaults. `out_summary` (struct_size set) may be NULL. err as avm_solve_file().
 * Failures: AVM_ERROR_INVALID_ARGUMENT (a path NULL; bad options or struct_size; an unknown
 *     input kind or output extension; .glb without options->avatar; options->solver for an
 *     input that is no landmark file; an input with no frames; a span or size avm_clip_write
 *     refuses),
 *   AVM_ERROR_IO (the input, the avatar or a table cannot be read; the output cannot be
 *     written), AVM_ERROR_PARSE (a malformed line ("FILE:LINE: ...") or .vrma; the avatar or a
 *     table malformed or unfit), AVM_ERROR_OUT_OF_MEMORY, AVM_ERROR_INTERNAL.
 * Thread-safe (separate files). */
AVATARMAP_C_API avm_status avm_convert_file(const char* input, const char* output,
                                            const avm_convert_options* options,
                                            avm_convert_summary* out_summary, char* err,
                                            size_t err_size);

/* ---- retargeting many poses ------------------------------------------------------------ */

/* As avm_retargeter_apply() for each of count poses: out_rotations gets count x joint_count x
 * 4 floats (pose after pose), out_hips_translation count x 3 (may be NULL). Allocation-free.
 * Failures: AVM_ERROR_INVALID_ARGUMENT (retargeter NULL; poses or out_rotations NULL with
 *   count > 0; count negative), AVM_ERROR_INTERNAL; avm_retargeter_last_error() says which. */
AVATARMAP_C_API avm_status avm_retargeter_apply_poses(avm_retargeter* r, const avm_pose* poses,
                                                      int64_t count, float* out_rotations,
                                                      float* out_hips_translation);

/* ---- capture of a whole file ----------------------------------------------------------- */

/* What avm_capture_file() did (also filled, as far as it got, when it fails). Set
 * struct_size = sizeof(avm_capture_summary) before the call (one that ends before `seconds` is
 * refused; the fields past the caller's struct_size are not written). */
typedef struct avm_capture_summary {
  uint32_t struct_size;
  int64_t frames;                                                        /* frames written */
  int64_t body_frames, left_hand_frames, right_hand_frames, face_frames; /* frames with each
                                          (max_people > 1: lines, one per person and frame) */
  int64_t frames_not_decoded; /* broken frames skipped with a warning */
  int32_t image_width, image_height;
  double fps;     /* the input's nominal rate; 0 unknown */
  double seconds; /* wall-clock time of the run, start-up included */
  /* -- added after seconds (a caller whose struct_size ends before them gets none) -- */
  /* Several people (avm_estimator_options.max_people > 1; all 0 with one): the distinct
   * person ids seen, the lines written (one per person in view and frame), and the frames
   * with at least one person in view. */
  int64_t people_ids, person_lines, frames_with_people;
} avm_capture_summary;

/* Called about twice a second during avm_capture_file() on its calling thread, and once at
 * the end of a successful run (done = total = the frames written): frames done, frames
 * expected (0 when unknown). */
typedef void (*avm_progress_fn)(void* user, int64_t done, int64_t total);

/* `avatarmap capture INPUT -o OUT` as a library call (the same library job as the CLI's
 * `capture`): a video file, an image, a folder of images or a printf pattern ("f%04d.png")
 * -> a *.landmarks.jsonl, written atomically (on failure an existing file is untouched).
 * Devices and streams are not accepted (INVALID_ARGUMENT). `options` NULL = the defaults of
 * avm_estimator_options_init() (hands and face on; threads 2 gives two lanes, threads 1 one
 * thread). `out_summary` (struct_size set) and `progress` may be NULL; `user` is passed to
 * `progress`. err as avm_solve_file().
 * Frames that cannot be decoded are skipped and counted (frames_not_decoded).
 * Failures: AVM_ERROR_INVALID_ARGUMENT (a path NULL, a device or stream, bad options or
 *   out_summary->struct_size, no models folder), AVM_ERROR_IO (the input cannot be opened or
 *   read, the output cannot be written, the models are missing), AVM_ERROR_PARSE (the input
 *   is not media FFmpeg can read, a model cannot be loaded), AVM_ERROR_UNSUPPORTED (built
 *   without ONNX Runtime or FFmpeg, a codec this FFmpeg lacks), AVM_ERROR_OUT_OF_MEMORY,
 *   AVM_ERROR_INTERNAL (the estimator failed on a frame: the message gives its time).
 *   Thread-safe (separate files). */
AVATARMAP_C_API avm_status avm_capture_file(const char* input, const char* out_landmarks,
                                            const avm_estimator_options* options,
                                            avm_capture_summary* out_summary,
                                            avm_progress_fn progress, void* user, char* err,
                                            size_t err_size);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* AVATARMAP_AVATARMAP_H */
