/* Internal state of the FFD lattice, shared by the lattice (ffd_lattice.c), the deformation
 * (ffd.c) and DM-FFD (dmffd.c). Not a public header. */
#ifndef CADMORPH_DEFORM_FFD_INTERNAL_H
#define CADMORPH_DEFORM_FFD_INTERNAL_H

#include "cadmorph/deform.h"

/* Bernstein degree cap per axis: the per-point basis buffers live on the stack. */
#define CM_FFD_MAX_AXIS 64

/* u may leave [0,1] by this much and still count as inside (then clamped onto the face). */
#define CM_FFD_INSIDE_TOL 1e-12

struct cm_ffd {
    int n[3];
    cm_ffd_basis basis;
    cm_ffd_knots knots;
    cm_ffd_local local;
    double origin[3];
    double a[9];    /* row-major axes (column j = a_j) */
    double ainv[9]; /* row-major inverse */
    double *knot[3]; /* B-spline: n + 4 knots per axis */
    double *xi[3];   /* Greville abscissae, n per axis */
    double *ctrl;    /* #ctrl x 3 control positions (reference or moved) */
    int moved;       /* ctrl differs from the reference: Newton */
    double cbox[6];  /* bounding box of ctrl: the lattice's image lies in their convex hull */
    size_t n_ctrl;
    double diag;     /* domain diagonal |a0 + a1 + a2|-ish: the Newton scale */
};

/* Basis of axis a at t: the values (and derivatives, if dn != NULL) of the non-zero
 * functions into nv/dn, returns the index of the first; *count gets how many (4 for
 * B-splines, n for Bernstein). t outside [0,1] extrapolates the end span's polynomial. */
int cm_ffd_axis_basis(const cm_ffd *f, int a, double t, double *nv, double *dn, int *count);

/* Local coordinates of one point; returns 1 inside, 0 outside, 2 failed; *iters: Newton
 * steps. */
int cm_ffd_locate(const cm_ffd *f, const double x[3], double u[3], int *iters);

#endif
