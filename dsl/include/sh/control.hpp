#pragma once
// Control flow recorded into the kernel, in Sh's spellings:
//   SH_IF(c) { ... } SH_ELSE { ... } SH_ENDIF;
//   SH_WHILE(c) { ... } SH_ENDWHILE;
//   SH_DO { ... } SH_UNTIL(c);
//   SH_FOR(Attrib1i i = 0, i < n, i += 1) { ... } SH_ENDFOR;
//   SH_BREAK(c); SH_CONTINUE(c);   (or without a condition)
// Plain C++ `if` and `for` run while recording: that is metaprogramming.
#include "sh/attrib.hpp"

namespace sh::detail {

void begin_if(const ValueHolder& c);
void begin_else();
void end_if();
void begin_while();
void while_condition(const ValueHolder& c);
void end_while();
void begin_do();
void begin_until();
void until_condition(const ValueHolder& c);
void begin_for();
void for_condition(const ValueHolder& c);
void for_body();
void end_for();
void emit_break();
void emit_break(const ValueHolder& c);
void emit_continue();
void emit_continue(const ValueHolder& c);

}  // namespace sh::detail

#define SH_IF(c) ::sh::detail::begin_if(c);
#define SH_ELSE ::sh::detail::begin_else();
#define SH_ENDIF ::sh::detail::end_if()
#define SH_WHILE(c)               \
  ::sh::detail::begin_while();    \
  ::sh::detail::while_condition(c);
#define SH_ENDWHILE ::sh::detail::end_while()
#define SH_DO ::sh::detail::begin_do();
#define SH_UNTIL(c)               \
  ::sh::detail::begin_until();    \
  ::sh::detail::until_condition(c)
#define SH_FOR(init, c, update)     \
  {                                 \
    init;                           \
    ::sh::detail::begin_for();      \
    ::sh::detail::for_condition(c); \
    update;                         \
    ::sh::detail::for_body();
#define SH_ENDFOR         \
  ::sh::detail::end_for(); \
  }
#define SH_BREAK(...) ::sh::detail::emit_break(__VA_ARGS__)
#define SH_CONTINUE(...) ::sh::detail::emit_continue(__VA_ARGS__)
