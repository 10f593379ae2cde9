/* pool.c - worker threads kept between jobs (pool.h). */
#include "core/pool.h"

#include <pthread.h>
#include <stdlib.h>

#define POOL_MAX 256

struct nc_pool {
    pthread_mutex_t lock;
    pthread_cond_t go, done;
    void *(*fn)(void *);
    void *arg;
    unsigned long job;  /* number of the job posted last */
    int running, stop;  /* workers still in the current job; 1: end */
    int n;
    pthread_t tid[POOL_MAX];
};

static void *pool_worker(void *arg)
{
    struct nc_pool *p = arg;
    unsigned long seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (p->job == seen && !p->stop)
            pthread_cond_wait(&p->go, &p->lock);
        if (p->stop)
            break;
        seen = p->job;
        void *(*fn)(void *) = p->fn;
        void *a = p->arg;
        pthread_mutex_unlock(&p->lock);
        fn(a);
        pthread_mutex_lock(&p->lock);
        if (--p->running == 0)
            pthread_cond_signal(&p->done);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

struct nc_pool *nc_pool_create(int nthreads)
{
    if (nthreads <= 1)
        return NULL;
    struct nc_pool *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->go, NULL);
    pthread_cond_init(&p->done, NULL);
    for (int i = 0; i < nthreads - 1 && i < POOL_MAX; i++) {
        if (pthread_create(&p->tid[p->n], NULL, pool_worker, p) != 0)
            break;
        p->n++;
    }
    return p;
}

void nc_pool_run(struct nc_pool *p, void *(*fn)(void *), void *arg)
{
    if (!p || p->n == 0) {
        fn(arg);
        return;
    }
    pthread_mutex_lock(&p->lock);
    p->fn = fn;
    p->arg = arg;
    p->running = p->n;
    p->job++;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->lock);
    fn(arg);
    pthread_mutex_lock(&p->lock);
    while (p->running > 0)
        pthread_cond_wait(&p->done, &p->lock);
    pthread_mutex_unlock(&p->lock);
}

void nc_pool_destroy(struct nc_pool *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&p->lock);
    p->stop = 1;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->lock);
    for (int i = 0; i < p->n; i++)
        pthread_join(p->tid[i], NULL);
    pthread_cond_destroy(&p->go);
    pthread_cond_destroy(&p->done);
    pthread_mutex_destroy(&p->lock);
    free(p);
}
