// Test-only library: loads fine but exports no facet_plugin_descriptor.
extern "C" __attribute__((visibility("default"))) int facet_test_not_a_plugin() { return 42; }
