/* scene.h - what is rendered: bodies (shape, material, pose), the Sun, the
 * camera and render settings, read from a YAML configuration.
 *
 * Frames: the scene frame is where the camera and body poses live. Each body
 * has a body-fixed frame; attitude_q rotates body-fixed vectors into the scene
 * frame and position_m is the body origin in the scene frame. The Sun is given
 * in the body-fixed frame of bodies[0]. All lengths in metres (double).
 */
#ifndef NC_SCENE_H
#define NC_SCENE_H

#include <stdint.h>

#include "core/config.h"
#include "core/pose.h"
#include "render/albedo_var.h"
#include "render/boulders.h"
#include "render/camera.h"
#include "render/craters.h"
#include "render/material.h"
#include "render/mesh.h"

#define NC_AU_M 149597870700.0     /* IAU 2012, exact */
#define NC_SOLAR_CONSTANT_W_M2 1361.0 /* total solar irradiance at 1 au */
#define NC_SUN_RADIUS_M 6.957e8       /* IAU 2015 nominal solar radius */
#define NC_MAX_BODIES 16

enum nc_shape_type { NC_SHAPE_SPHERE, NC_SHAPE_ELLIPSOID, NC_SHAPE_MESH, NC_SHAPE_ASTEROID };

struct nc_body {
    char name[64];
    enum nc_shape_type shape;
    struct nc_vec3 radii_m; /* sphere/ellipsoid semi-axes along body x, y, z */
    struct nc_mesh mesh;    /* mesh and asteroid */
    int smooth_normals;     /* mesh and asteroid: shade with normals interpolated from the vertices' */
    struct nc_boulder_field boulders; /* none when boulders.n == 0 (meshes only) */
    struct nc_crater_field craters;   /* carved into the mesh (oldest first); none when craters.n == 0 */
    /* Procedural albedo variation (meshes only): its parameters, and the
     * ground's factor per mesh vertex (NULL: none). */
    struct nc_albedo_var_params albedo_var;
    float *albedo_vertex;
    double bounding_radius_m;
    struct nc_material material;
    struct nc_vec3 position_m; /* scene frame */
    struct nc_quat attitude_q; /* body-fixed -> scene */
    struct nc_vec3 velocity_m_s;           /* scene frame */
    struct nc_vec3 angular_velocity_rad_s; /* body-fixed frame */
};

/* Whether body b is a triangle mesh (a loaded shape model, a DEM or the
 * procedural asteroid), not an analytic sphere or ellipsoid. */
static inline int nc_body_is_mesh(const struct nc_body *b)
{
    return b->shape == NC_SHAPE_MESH || b->shape == NC_SHAPE_ASTEROID;
}

struct nc_sun {
    int has_position;
    struct nc_vec3 direction;   /* unit, toward the Sun, bodies[0] frame (when !has_position) */
    struct nc_vec3 position_m;  /* bodies[0] frame (when has_position) */
    double irradiance_w_m2;     /* at bodies[0] (direction) or at 1 au scaled by 1/d^2 (position) */
    int irradiance_override;
    double distance_m;          /* from bodies[0] (direction: sun.distance_au; position: |position_m|) */
};

struct nc_render_settings {
    int samples_per_pixel; /* a square number: n x n strata */
    uint64_t seed;
    int threads; /* 0 = all cores */
    /* Meshes: the coarsest level of detail whose surface error is at most
     * this many pixels at the body's nearest range; 0 = always the full mesh. */
    double lod_error_px;
    /* Boulders: only rocks whose longest dimension spans at least this many
     * pixels at the body's nearest range are traced; 0 = every rock; < 0
     * (the default) = 1 for a body whose material folds the rest into its
     * reflectance, 0 for others (nc_scene_boulder_min_px). */
    double boulder_min_px;
    int boulder_fold; /* 1 (default): fold the rocks not traced into the reflectance */
    /* Rough-faced boulders spanning at least this many pixels at their
     * distance from the camera are traced as detailed surfaces (the relief
     * in geometry), the others as flat-faced polyhedra with the relief in
     * their shading; 0 = never. */
    double boulder_mesh_px;
    int soft_shadows; /* 1: shadow rays toward points of the solar disk (penumbrae); 0: its centre */
    /* Indirect light: path vertices after the camera ray's (0: direct
     * sunlight only), and how many are traced before Russian roulette. */
    int bounces;
    int roulette_after;
    /* 1: camera/quality.h picks samples_per_pixel, bounces and soft_shadows
     * per frame from the camera's noise (render.quality: auto); 0: as set. */
    int quality_auto;
    double auto_noise_fraction; /* auto: the RMS render error allowed, in units of the camera's noise */
};

struct nc_scene {
    struct nc_body body[NC_MAX_BODIES];
    int nbodies;
    struct nc_sun sun;
    struct nc_camera camera;
    struct nc_render_settings render;
};

/* The built-in default scene (YAML text) used when no file is given. */
extern const char nc_default_scene_yaml[];

/* Build a scene from a loaded configuration; every key must be consumed. */
int nc_scene_from_config(struct nc_cfg *cfg, struct nc_scene *s);
/* The same without the unknown-key check, for callers that read further
 * sections (optics, sensor, ...) and check afterwards. */
int nc_scene_read(struct nc_cfg *cfg, struct nc_scene *s);
/* nc_scene_read in its two steps: the camera, Sun and render sections, each
 * checked for unknown keys (they have no other reader); then the bodies:
 * every body's keys read and checked (nothing built), then each built
 * (meshes, craters, rocks: seconds for a large scene). A caller reads its
 * own sections between the two, so that a mistake in any of them is
 * reported before the build. Each frees s on failure. */
int nc_scene_read_view(struct nc_cfg *cfg, struct nc_scene *s);
int nc_scene_read_bodies(struct nc_cfg *cfg, struct nc_scene *s);
/* Between the two, once the caller has read its own sections: a top-level
 * key that no reader takes (a misspelt section) is an error then, before
 * the bodies are built. */
int nc_scene_check_sections(struct nc_cfg *cfg);
/* Load file (NULL = built-in default scene) and apply overrides. */
int nc_cfg_load_scene(struct nc_cfg *cfg, const char *path, const char *const *sets, int nsets);
/* Convenience: load file (NULL = built-in default), apply overrides, build. */
int nc_scene_load(const char *path, const char *const *sets, int nsets, struct nc_scene *s);
void nc_scene_free(struct nc_scene *s);
/* A body's craters and boulders from its config item and shape node, after
 * its shape is built (scene_detail.c; internal to scene*.c). dry: every key
 * read and checked, nothing built (the shape was read dry too). */
int nc__scene_detail_from_config(struct nc_cfg_node *item, struct nc_cfg_node *shape, struct nc_body *b, int dry);
/* The error just set (by a loader or generator) restated at config node n,
 * with its file and line (scene_detail.c). */
int nc__scene_error_at(const struct nc_cfg_node *n);
/* Shapes `dem` and `globe` as meshes (scene_dem.c; internal to scene*.c);
 * dry: their keys alone, no image read. */
int nc__scene_dem_from_config(struct nc_cfg_node *shape, int globe, struct nc_body *b, int dry);

/* The Sun's angular radius seen from bodies[0] (the penumbrae on the
 * bodies), and from scene point p, radians (sun.distance_m away for a Sun
 * given by its direction). */
double nc_scene_sun_radius_rad(const struct nc_scene *s);
double nc_scene_sun_radius_from(const struct nc_scene *s, struct nc_vec3 p);

/* The boulder cut of body b in pixels (render.boulder_min_px resolved). */
double nc_scene_boulder_min_px(const struct nc_scene *s, int b);

/* Poses dt seconds later: positions move with their velocities, attitudes
 * turn at their angular rates. out shares s's meshes and materials (a shallow
 * copy for rendering; never free it). */
void nc_scene_propagate(const struct nc_scene *s, double dt, struct nc_scene *out);
/* q turned by angular velocity w (expressed in q's own frame) for dt. */
struct nc_quat nc_quat_propagate(struct nc_quat q, struct nc_vec3 w, double dt);

/* Sun, in the scene frame, seen from scene point p: unit direction toward the
 * Sun and the solar irradiance there (W m^-2). */
void nc_scene_sun_at(const struct nc_scene *s, struct nc_vec3 p, struct nc_vec3 *dir, double *irradiance_w_m2);

/* The scene's configured pose at time t_ns (the emulator's pose before any
 * has arrived), and a pose applied to the scene: camera, Sun and bodies[0]
 * (scene_pose.c). A pose's Sun position keeps the configured irradiance law. */
void nc_scene_pose(const struct nc_scene *s, int64_t t_ns, struct nc_pose *p);
void nc_scene_apply_pose(struct nc_scene *s, const struct nc_pose *p);
/* A pose that carries no body pose (has_body 0: a message without
 * BODY_POSE) given bodies[0]'s configured position and attitude, so that
 * it interpolates with and records the pose the frame uses. */
void nc_scene_pose_body(const struct nc_scene *s, struct nc_pose *p);

#endif
