// A shared library without the plugin entry point (tests/plugin_test.cpp): loading it is a
// one-line error naming the missing symbol.
extern "C" __attribute__((visibility("default"))) int not_a_hairbench_plugin(void) { return 0; }
