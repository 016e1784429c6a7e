#include "sh/control.hpp"

#include "recorder.hpp"
#include "sh/error.hpp"

namespace sh::detail {
namespace {

Recorder& in_program(const char* macro) {
  Recorder* r = current_recorder();
  if (!r) throw Error(std::string(macro) + " used outside SH_BEGIN_PROGRAM ... SH_END");
  return *r;
}

}  // namespace

void begin_if(const ValueHolder& c) { in_program("SH_IF").begin_if(c.value()); }
void begin_else() { in_program("SH_ELSE").begin_else(); }
void end_if() { in_program("SH_ENDIF").end_if(); }
void begin_while() { in_program("SH_WHILE").begin_while(); }
void while_condition(const ValueHolder& c) { in_program("SH_WHILE").while_condition(c.value()); }
void end_while() { in_program("SH_ENDWHILE").end_while(); }
void begin_do() { in_program("SH_DO").begin_do(); }
void begin_until() { in_program("SH_UNTIL").begin_until(); }
void until_condition(const ValueHolder& c) { in_program("SH_UNTIL").until_condition(c.value()); }
void begin_for() { in_program("SH_FOR").begin_for(); }
void for_condition(const ValueHolder& c) { in_program("SH_FOR").for_condition(c.value()); }
void for_body() { in_program("SH_FOR").for_body(); }
void end_for() { in_program("SH_ENDFOR").end_for(); }
void emit_break() { in_program("SH_BREAK").emit_break(); }
void emit_continue() { in_program("SH_CONTINUE").emit_continue(); }

void emit_break(const ValueHolder& c) {
  Recorder& r = in_program("SH_BREAK");
  r.begin_if(c.value());
  r.emit_break();
  r.end_if();
}

void emit_continue(const ValueHolder& c) {
  Recorder& r = in_program("SH_CONTINUE");
  r.begin_if(c.value());
  r.emit_continue();
  r.end_if();
}

}  // namespace sh::detail
