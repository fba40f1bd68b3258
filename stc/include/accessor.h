/* Variable access, for code written against matiec's accessor.h (e.g. a
** runtime's symbol table): stc stores variables as plain fields, so
** __GET_VAR(x) is x itself and &__GET_VAR(x) its address. */
#ifndef ACCESSOR_H
#define ACCESSOR_H

#define __GET_VAR(name, ...) name __VA_ARGS__
#define __SET_VAR(prefix, name, suffix, new_value) prefix name suffix = (new_value)

/* Inside a {{ }} pragma of a FUNCTION_BLOCK or PROGRAM body. */
#define GetFbVar(var, ...) (data__->var __VA_ARGS__)
#define SetFbVar(var, val, ...) (data__->var __VA_ARGS__ = (val))

#endif
