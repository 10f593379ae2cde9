/* timeline.h - the pose timeline: poses buffered with their simulation times,
 * and the pose at any instant: linear interpolation of positions and rates,
 * spherical linear interpolation (slerp) of attitudes, extrapolation with the
 * rates beyond the newest pose up to a configured limit.
 * Single-threaded: the caller serialises access. No I/O, no allocation after
 * init.
 */
#ifndef NC_TIMELINE_H
#define NC_TIMELINE_H

#include <stddef.h>
#include <stdint.h>

#include "core/pose.h"
#include "navcam/protocol.h"

struct nc_timeline {
    struct nc_pose *ring;
    size_t cap, n, head; /* head: index of the oldest pose */
    int64_t max_extrapolation_ns;
};

int nc_timeline_init(struct nc_timeline *tl, size_t capacity, int64_t max_extrapolation_ns);
void nc_timeline_free(struct nc_timeline *tl);
/* The pose a message carries. */
void nc_pose_from_msg(const struct nc_pose_msg *m, struct nc_pose *p);
/* Append a pose. Times must not go backwards (NC_REJECT_TIME_BACKWARDS); a
 * pose at the newest time replaces it. When full, the oldest pose is dropped. */
enum nc_reject nc_timeline_push(struct nc_timeline *tl, const struct nc_pose *p);
/* The pose at t_ns; *gap_ns (may be NULL) is how far t lies outside the
 * buffered span (0 inside). */
enum nc_pose_quality nc_timeline_at(const struct nc_timeline *tl, int64_t t_ns, struct nc_pose *out, int64_t *gap_ns);

/* Spherical linear interpolation along the shorter arc, s in [0, 1]. */
struct nc_quat nc_quat_slerp(struct nc_quat a, struct nc_quat b, double s);

#endif
