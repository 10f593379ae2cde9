/* sumfile.h - SPC (Gaskell stereophotoclinometry) SUM files: the picture
 * geometry missions publish with their images. Parsing only; what the
 * numbers mean for a NavCam camera is render/camera.c's business.
 *
 * Layout (one item per line, each line ending with its label; numbers in
 * Fortran D or E notation): picture name; UTC; "NPX NLN THRSH THRSH";
 * "MMFL CTR_sample CTR_line"; SCOBJ; CX; CY; CZ; SZ; K-MATRIX (six numbers);
 * DISTORTION (four, optional); then SIGMA_VSO, SIGMA_PTG, LANDMARKS ...,
 * LIMB FITS ..., END FILE, which are not used. Conventions (docs/sumfiles.md):
 *   SCOBJ  spacecraft -> body centre, body-fixed frame, km (the camera is
 *          at -SCOBJ)
 *   CX CY CZ  unit vectors, body-fixed: the rows of the body -> camera
 *          rotation; CZ the boresight
 *   SZ     unit vector body -> Sun, body-fixed
 *   MMFL   focal length, mm; K-MATRIX K11 K12 K13 K21 K22 K23, pixels/mm
 *   CTR    principal point, 1-based (sample, line) with pixel centres at
 *          whole numbers
 * A body-fixed point P (km) is seen at V = P + SCOBJ, x = MMFL (CX.V)/(CZ.V),
 * y = MMFL (CY.V)/(CZ.V), sample = CTR1 + K11 x + K12 y,
 * line = CTR2 + K21 x + K22 y.
 */
#ifndef NC_SUMFILE_H
#define NC_SUMFILE_H

#include "core/vec.h"

/* How far from unit length, and from perpendicular (dot product), CX, CY
 * and CZ may be: such a set is made exactly orthonormal. */
#define NC_SUMFILE_AXES_TOL 1e-3

struct nc_sumfile {
    char picture[64];
    char utc[64];
    int npx, nln;        /* samples per line, lines */
    double mmfl_mm;
    double ctr[2];       /* 1-based sample, line */
    double scobj_km[3];
    double cx[3], cy[3], cz[3];
    double sz[3];
    double k[6];         /* K11 K12 K13 K21 K22 K23, pixels/mm */
    struct nc_quat q;    /* camera -> body: CX, CY, CZ made orthonormal (nc_sumfile_rotation) */
};

/* Read and check a SUM file: every required item present once with its
 * count of numbers, each a number; the camera axes orthonormal and
 * right-handed (nc_sumfile_rotation); SZ not zero; K11 and K22 not zero;
 * what NavCam's camera does not model absent: K13 = K23 = 0, a skew (K12,
 * K21) moving no pixel by more than 0.05 px over the image (then taken as
 * none), DISTORTION (if given) all 0. Errors name the file, the line and
 * the item. */
int nc_sumfile_read(const char *path, struct nc_sumfile *out);

/* The camera -> body rotation whose columns are the axes ax[0..2] (CX, CY,
 * CZ, body-fixed): each of unit length and the three perpendicular within
 * NC_SUMFILE_AXES_TOL, right-handed, then made exactly orthonormal keeping
 * CZ (a point on the boresight stays at CTR, as SPC's projection puts it)
 * and CX's plane with it. 0, or NC_ECONFIG with a message naming the axis
 * (not the file: the caller's), and *item the axis at fault (0..2). */
int nc_sumfile_rotation(const double *const ax[3], struct nc_quat *q, int *item);

/* Write s as a SUM file (E notation, the labels above); for tests and for
 * turning other pose sources into SUM files. */
int nc_sumfile_write(const char *path, const struct nc_sumfile *s);

#endif
