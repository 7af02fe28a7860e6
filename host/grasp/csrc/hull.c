/* tsukami-grasp: the one C entry point into Qhull (src/hull.rs calls it).
 *
 * A flat interface, so the Rust side declares one function by hand and needs no
 * bindgen: points in, each facet's unit outward normal and offset out (through
 * a callback), optionally each vertex's input index. Qhull's errors unwind by
 * longjmp inside qh_new_qhull, never across the Rust frames; the exit code is
 * returned. Same options as before ("qhull": Qhull's defaults).
 */
#include "libqhull_r.h"

#include <stdarg.h>
#include <stdio.h>

/* Replaces userprintf_r.c: Qhull prints nothing (errors, warnings and traces
 * would go to the caller's stderr); error codes are still recorded. */
void qh_fprintf(qhT *qh, FILE *fp, int msgcode, const char *fmt, ...) {
  (void)fp;
  (void)fmt;
  if (qh && msgcode >= MSG_ERROR && msgcode < MSG_WARNING) {
    qh->last_errcode = msgcode;
  }
}

typedef void (*tsukami_facet_fn)(void *ctx, const double *normal, double offset);
typedef void (*tsukami_vertex_fn)(void *ctx, int point_index);

/* Convex hull of num_points points of dimension dim (row-major in points,
 * read only by Qhull with these options). Calls on_facet for every facet
 * (normal . x + offset <= 0 inside) and, when on_vertex is not NULL,
 * on_vertex for every hull vertex with its index in points.
 * Returns 0, or Qhull's exit code (nothing was reported then). */
int tsukami_qhull_hull(int dim, int num_points, double *points, void *ctx,
                       tsukami_facet_fn on_facet, tsukami_vertex_fn on_vertex) {
  qhT qh_qh;
  qhT *qh = &qh_qh;
  facetT *facet;
  vertexT *vertex;
  int exitcode, curlong, totlong;
  char command[] = "qhull";

  qh_zero(qh, stderr);
  exitcode = qh_new_qhull(qh, dim, num_points, points, False, command, NULL, stderr);
  if (!exitcode) {
    FORALLfacets {
      on_facet(ctx, facet->normal, facet->offset);
    }
    if (on_vertex) {
      FORALLvertices {
        on_vertex(ctx, qh_pointid(qh, vertex->point));
      }
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  qh_memfreeshort(qh, &curlong, &totlong);
  return exitcode;
}
