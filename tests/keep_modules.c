/* Preloaded into the viewer under LeakSanitizer: turns dlclose into a no-op so that the GL
 * driver's modules stay mapped at exit. Their own leftover allocations can then be named in the
 * suppression file; once unloaded they show as "<unknown module>" and cannot be told apart from
 * ours. */
int dlclose(void *handle);
int dlclose(void *handle) {
    (void)handle;
    return 0;
}
