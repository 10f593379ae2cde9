/* pool.h - a pool of worker threads kept between jobs: a job runs one
 * function on every thread of the pool and on the caller at once, and
 * returns when all have returned. Threads start once (nc_pool_create) and
 * sleep between jobs, so a job costs a wake-up, not a thread start.
 *
 * The function divides the work itself (e.g. an atomic counter over tiles);
 * a pool that could not start all its threads runs with fewer, which only
 * costs time. One job at a time per pool. */
#ifndef NC_POOL_H
#define NC_POOL_H

struct nc_pool;

/* A pool of nthreads - 1 workers (the caller is the n-th); NULL when
 * nthreads <= 1 or on failure: nc_pool_run then runs fn on the caller only. */
struct nc_pool *nc_pool_create(int nthreads);
void nc_pool_run(struct nc_pool *p, void *(*fn)(void *), void *arg);
void nc_pool_destroy(struct nc_pool *p);

#endif
