#define _DEFAULT_SOURCE
#include "threadpool.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

struct threadpool {
    int num_threads;
    pthread_t *threads;
    pthread_mutex_t lock;
    pthread_cond_t wake; /* workers wait here for a new job */
    pthread_cond_t done; /* the caller waits here for the job's end */
    /* the current job, published under lock */
    task_fn fn;
    void *ctx;
    int num_tasks;
    unsigned long generation;
    int active; /* workers still inside the current job */
    int quit;
    atomic_int next_task;
};

typedef struct {
    threadpool *pool;
    int index;
} worker_arg;

static void *worker_main(void *p) {
    worker_arg arg = *(worker_arg *)p;
    free(p);
    threadpool *pool = arg.pool;
    unsigned long seen = 0;
    pthread_mutex_lock(&pool->lock);
    for (;;) {
        while (!pool->quit && pool->generation == seen) pthread_cond_wait(&pool->wake, &pool->lock);
        if (pool->quit) break;
        seen = pool->generation;
        task_fn fn = pool->fn;
        void *ctx = pool->ctx;
        int n = pool->num_tasks;
        pthread_mutex_unlock(&pool->lock);
        for (int t; (t = atomic_fetch_add(&pool->next_task, 1)) < n;) fn(ctx, t, arg.index);
        pthread_mutex_lock(&pool->lock);
        if (--pool->active == 0) pthread_cond_signal(&pool->done);
    }
    pthread_mutex_unlock(&pool->lock);
    return NULL;
}

int threadpool_num_cores(void) {
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

threadpool *threadpool_create(int num_threads) {
    if (num_threads <= 0) num_threads = threadpool_num_cores();
    threadpool *pool = calloc(1, sizeof(threadpool));
    if (!pool) return NULL;
    pool->threads = calloc((size_t)num_threads, sizeof(pthread_t));
    if (!pool->threads) {
        free(pool);
        return NULL;
    }
    pthread_mutex_init(&pool->lock, NULL);
    pthread_cond_init(&pool->wake, NULL);
    pthread_cond_init(&pool->done, NULL);
    atomic_init(&pool->next_task, 0);
    for (int i = 0; i < num_threads; i++) {
        worker_arg *arg = malloc(sizeof(worker_arg));
        if (arg) *arg = (worker_arg){pool, i};
        if (!arg || pthread_create(&pool->threads[i], NULL, worker_main, arg) != 0) {
            free(arg);
            threadpool_destroy(pool);
            return NULL;
        }
        pool->num_threads = i + 1;
    }
    return pool;
}

void threadpool_destroy(threadpool *pool) {
    if (!pool) return;
    pthread_mutex_lock(&pool->lock);
    pool->quit = 1;
    pthread_cond_broadcast(&pool->wake);
    pthread_mutex_unlock(&pool->lock);
    for (int i = 0; i < pool->num_threads; i++) pthread_join(pool->threads[i], NULL);
    pthread_cond_destroy(&pool->done);
    pthread_cond_destroy(&pool->wake);
    pthread_mutex_destroy(&pool->lock);
    free(pool->threads);
    free(pool);
}

int threadpool_size(const threadpool *pool) { return pool->num_threads; }

void threadpool_run(threadpool *pool, task_fn fn, void *ctx, int num_tasks) {
    if (num_tasks <= 0) return;
    pthread_mutex_lock(&pool->lock);
    pool->fn = fn;
    pool->ctx = ctx;
    pool->num_tasks = num_tasks;
    atomic_store(&pool->next_task, 0);
    pool->active = pool->num_threads;
    pool->generation++;
    pthread_cond_broadcast(&pool->wake);
    while (pool->active > 0) pthread_cond_wait(&pool->done, &pool->lock);
    pthread_mutex_unlock(&pool->lock);
}
