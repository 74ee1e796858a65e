#pragma once
/// @file
/// For programs that run Fast DDS under AddressSanitizer (the sanitizer test build): Debian's
/// Fast DDS 2.9 deletes a StatisticsReaderImpl through a pointer to a smaller base class at every
/// DataReader's deletion (new-delete-type-mismatch inside libfastrtps, not in egress). Include
/// this header in exactly one source file of such a program (its main): that one check is off by
/// default; every other check, and whatever ASAN_OPTIONS sets, stay as they are.

#if defined(__SANITIZE_ADDRESS__)
extern "C" const char* __asan_default_options() {
  return "new_delete_type_mismatch=0";
}
#endif
