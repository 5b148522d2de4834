/* mpm_pressure: follower pressures on MPM bodies, on the points of a
 * loaded surface (mpm_traction.h): on a named surface, each facet's force
 * is the pressure on its deformed area vector, the facet's corners carried
 * by the particles nearest them; on a face of domain.box, -p cof(F) N dA
 * with the carrier's F.  The explicit state's forces, the grid's (the
 * implicit MPM's) and their tangent. */
#ifndef MPM_PRESSURE_H
#define MPM_PRESSURE_H

#include "mpm_conditions.h"
#include "mpm_grid.h"

struct mpm_model;
struct mpm_state;

/* f += the force of pressure pv (Pa, at the point's reference place) of
 * condition bc at its k-th point, over the explicit state st (the
 * particles' positions and F). */
void mpm_pressure_state(const struct mpm_model *m, struct mpm_state *st,
                        const mpm_bc *bc, long k, double pv, double f[3]);

/* The same over the particles at base positions xb moved by the nodal
 * displacements u of grid g (NULL: none), F = I + sum_I u_I grad N_I. */
void mpm_pressure_grid(const struct mpm_model *m, const mpm_grid *g,
                       const double *xb, const double *u, const mpm_bc *bc,
                       long k, double pv, double f[3]);

/* An entry of a tangent: v at (row, col), grid dofs 3 node + component. */
typedef void (*mpm_pressure_entry)(void *ctx, long row, long col, double v);

/* The tangent of the nodal force -w_a f of mpm_pressure_grid spread at
 * the particle at xs (w_a its weights on g), d(-w_a f_i)/d u_Jc, entry by
 * entry (not symmetric). */
void mpm_pressure_tangent(const struct mpm_model *m, const mpm_grid *g,
                          const double *xb, const double *u, const mpm_bc *bc,
                          long k, double pv, const double xs[3],
                          mpm_pressure_entry add, void *ctx);

#endif
