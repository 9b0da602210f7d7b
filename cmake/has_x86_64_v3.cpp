// Configure-time probe (CMakeLists.txt, GRAINLINK_ARCH=auto): exits 0 where the processor has
// the x86-64-v3 instruction set.
int main() {
    __builtin_cpu_init();
    return __builtin_cpu_supports("x86-64-v3") ? 0 : 1;
}
