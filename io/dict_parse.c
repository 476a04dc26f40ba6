/* placeholder */
typedef int mf_placeholder_dict_parse;
