/* registry.c: placeholder, being written. */
typedef int mf_placeholder_registry;
