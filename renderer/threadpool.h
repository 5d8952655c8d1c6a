/* glint — a small fixed thread pool: a job is N tasks handed out by an atomic counter. */
#ifndef GLINT_THREADPOOL_H
#define GLINT_THREADPOOL_H

/* task(ctx, task_index, worker_index); worker_index < threadpool_size() indexes per-thread scratch. */
typedef void (*task_fn)(void *ctx, int task, int worker);

typedef struct threadpool threadpool;

/* num_threads <= 0: one per online core. Returns NULL when threads cannot be started. */
threadpool *threadpool_create(int num_threads);
void threadpool_destroy(threadpool *pool);
int threadpool_size(const threadpool *pool);
/* Runs fn for tasks 0..num_tasks-1 on the pool's threads and returns when all are done. Not
 * re-entrant: one job at a time per pool. */
void threadpool_run(threadpool *pool, task_fn fn, void *ctx, int num_tasks);
/* Number of online cores (at least 1). */
int threadpool_num_cores(void);

#endif
