// stereobench command line (placeholder main until the subcommands land).
#include <cstdio>
int main() { return 0; }
