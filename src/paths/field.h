/* The field a path descends inside a face (field.c): T on the face
 * unfolded into its plane, as the quadratic fitted to six values (paper
 * section 5) or the face's linear interpolant. */
#ifndef MFMM_PATHS_FIELD_H
#define MFMM_PATHS_FIELD_H

#include "state.h"

/* One face unfolded into its plane, with its interpolants of T. */
typedef struct frame {
    int32_t f;
    int32_t v[3];
    int degenerate;
    double e1[3], e2[3];  /* in-plane axes; corner 0 at the origin */
    double P[3][2];       /* corners in the plane */
    double gb[3][2];      /* gradients of the barycentric coordinates */
    double T[3];
    int lin_ok;           /* all three corners finite */
    double glin[2];       /* linear gradient */
    int quad_ok;          /* quadratic fit usable */
    double c[6];          /* T = c0 + c1 x + c2 y + c3 x^2 + c4 xy + c5 y^2, normalized coords */
    double ox, oy, scale; /* normalization: (p - o) / scale */
    double max_edge;
    double F;             /* face cost (per face), or mean of corner costs */
} frame;

/* Reads T[v], refusing NaN. */
int mfmm_path_read_T(tracer *t, int32_t v, double *out);

/* F at barycentric b of face f (1 without cost; the costs were checked
 * when the call began, mfmm_check_cost). */
double mfmm_path_cost_at(const tracer *t, int32_t f, const double b[3]);

/* Builds face f's frame and interpolants. 0 on a bad input value. */
int mfmm_path_frame_build(tracer *t, int32_t f, frame *fr);

/* grad T at plane point p: the quadratic where usable and descending like
 * the linear gradient, else the linear one. 0 when there is none. */
int mfmm_path_field_grad(const frame *fr, const double p[2], double g[2]);

void mfmm_path_bary_to_plane(const frame *fr, const double b[3], double p[2]);

double mfmm_path_frame_T(const frame *fr, const double b[3]);

#endif
