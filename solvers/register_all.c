/* placeholder */
typedef int mf_placeholder_register_all;
