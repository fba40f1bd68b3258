/*
** stc: a Structured Text (IEC 61131-3) to C compiler, drop-in for matiec's iec2c.
** Pipeline: lex (lexer.c) -> parse (parser.c) -> check (sema.c) -> emit (codegen.c).
** This header holds what the stages share: diagnostics, tokens, the syntax tree
** and the semantic types.
*/
#ifndef STC_H
#define STC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define STC_VERSION "0.1.0"

/* ---- memory and strings (util.c) ---- */
void *xalloc(size_t n);                 /* zeroed; exits on exhaustion */
void xfree_all(void);                   /* frees everything xalloc gave */
char *xstrdup(const char *s);
char *xstrndup(const char *s, size_t n);
char *fmt(const char *f, ...) __attribute__((format(printf, 1, 2)));
char *upcase(const char *s);

typedef struct { void **v; int n, cap; } Vec;
void vec_push(Vec *v, void *p);
void vec_remove(Vec *v, int i);          /* keeps the order */

typedef struct { char *s; size_t n, cap; } Buf;   /* growable text */
void buf_put(Buf *b, const char *s);
void buf_printf(Buf *b, const char *f, ...) __attribute__((format(printf, 2, 3)));

/* ---- diagnostics (util.c) ---- */
typedef struct Source { const char *name, *text; size_t len; } Source;
typedef struct { const Source *src; int line, col; } Loc;

/* Print "file:line:col: error: msg", the source line and a caret. */
void error_at(Loc loc, const char *f, ...) __attribute__((format(printf, 2, 3)));
/* "file:line:col: warning: msg" and the line; compilation goes on. */
void warning_at(Loc loc, const char *f, ...) __attribute__((format(printf, 2, 3)));
/* Same as error_at, then exit(1). */
_Noreturn void fatal_at(Loc loc, const char *f, ...) __attribute__((format(printf, 2, 3)));
extern int error_count;
/* When set, fatal errors jump here instead of exiting (for embedding and fuzzing). */
#include <setjmp.h>
extern jmp_buf *stc_error_jmp;
#define MAX_ERRORS 20

/* ---- tokens (lexer.c) ---- */
typedef enum {
    TK_IDENT,    /* identifier or keyword; up holds it upper-cased */
    TK_INT,      /* integer literal: ival */
    TK_REAL,     /* real literal: rval */
    TK_STRING,   /* 'string': sval (escapes resolved), slen */
    TK_TIME,     /* T#, TOD#, D#, DT# literal: tval (ns), tkind */
    TK_PUNCT,    /* operator or punctuation: up holds it */
    TK_LOCATION, /* %IX0.1 etc: text */
    TK_PRAGMA,   /* {{ C code }} or { C code }: sval; ival 1 for the single-brace form */
    TK_EOF,
} TokKind;

typedef enum { TIMEK_TIME, TIMEK_DATE, TIMEK_TOD, TIMEK_DT } TimeKind;

typedef struct Token {
    TokKind kind;
    Loc loc;
    char *text;   /* as written */
    char *up;     /* upper-cased text (identifiers, punctuation) */
    uint64_t ival;
    bool ioverflow;
    double rval;
    int64_t tval;
    TimeKind tkind;
    char *sval;
    int slen;
    size_t pos, end;   /* where it lies in its source text: [pos, end) */
} Token;

Token *lex(const Source *src, int *count);
bool is_reserved(const char *up);

/* ---- syntax tree (parser.c) ---- */
typedef struct Type Type;
typedef struct Node Node;
typedef struct Sym Sym;
typedef struct Pou Pou;

typedef enum {
    /* expressions */
    N_INT, N_REAL, N_BOOL, N_STRING, N_TIME,
    N_TYPED,      /* TYPE#literal or Enum#Value: tname + lhs (literal) or name */
    N_IDENT, N_MEMBER, N_INDEX, N_CALL, N_UNARY, N_BINARY,
    N_ARRINIT,    /* [a, n(b), ...] : list of items; N_REPEAT items */
    N_REPEAT,     /* count(value) in an array initializer */
    N_STRUCTINIT, /* (a := 1, b := 2) : list of N_ARG */
    N_ARG,        /* call argument or struct init item: name (may be NULL), lhs, is_out, negated */
    /* statements */
    S_ASSIGN, S_CALL, S_IF, S_CASE, S_FOR, S_WHILE, S_REPEAT, S_EXIT, S_RETURN,
    S_PRAGMA, S_EMPTY,
    S_CASEITEM,   /* labels (list of N_RANGE or exprs) + body */
    N_RANGE,      /* lo..hi */
    S_LABEL,      /* IL label: name; ival 1 when a jump goes there */
    S_GOTO,       /* IL jump to the label name */
} NodeKind;

struct Node {
    NodeKind kind;
    Loc loc;      /* operator or keyword */
    Loc start;    /* first token of the construct */
    const char *op;   /* operator spelling (upper-case) */
    char *name;   /* identifier as written */
    char *uname;  /* upper-cased */
    char *tname;  /* typed-literal prefix */
    Node *lhs, *rhs, *third, *fourth;
    Vec list;     /* args, statements, items... */
    Vec list2;    /* IF: blocks; CASE: items */
    Node *els;    /* ELSE body (S_EMPTY list holder) */
    /* literal values */
    uint64_t ival; bool neg; bool ioverflow;
    double rval;
    int64_t tval; TimeKind tkind;
    char *sval; int slen;
    bool is_out, negated;
    int depth;        /* operator nesting below this node */
    /* filled by sema */
    Type *ty;
    Sym *sym;         /* resolved identifier / member */
    Pou *callee;      /* called POU (user function or FB type) */
    int builtin;      /* builtin function id, when > 0 */
    Type *conv_from;  /* builtin conversions and generic functions: operand type */
    Node *en, *eno;   /* standard function calls: EN := input, ENO => target */
    const char *libfn;  /* B_LIB: the C helper */
    Node *opx;        /* operator functions (ADD, GT, ...): the operator expression they mean */
    bool is_const;    /* constant expression */
    int64_t cval;     /* its integer value when is_const */
};

typedef enum { TS_NAME, TS_ARRAY, TS_STRUCT, TS_ENUM, TS_SUBRANGE, TS_STRING } TSKind;
typedef struct TypeSpec {
    TSKind kind;
    Loc loc;
    char *name;           /* TS_NAME: type name; TS_SUBRANGE: base */
    Vec dims;             /* TS_ARRAY: N_RANGE nodes */
    struct TypeSpec *elem;
    Vec fields;           /* TS_STRUCT: VarDecl */
    Vec values;           /* TS_ENUM: Token* (names) */
    Node *lo, *hi;        /* TS_SUBRANGE */
    Node *strlen_;        /* TS_STRING: STRING[n] */
    Type *resolved;
} TypeSpec;

typedef enum {
    V_INPUT, V_OUTPUT, V_IN_OUT, V_LOCAL, V_TEMP, V_EXTERNAL, V_GLOBAL, V_FIELD
} VarClass;

typedef struct VarDecl {
    char *name, *uname;
    Loc loc;
    VarClass cls;
    bool constant, retain, non_retain;
    char *location;       /* "%QW3" or NULL */
    Loc locloc;
    TypeSpec *spec;
    Node *init;
} VarDecl;

typedef enum { POU_FUNCTION, POU_FB, POU_PROGRAM } PouKind;

struct Pou {
    PouKind kind;
    char *name, *uname;
    Loc loc;
    TypeSpec *ret;        /* functions */
    Type *rettype;
    Vec vars;             /* VarDecl */
    Vec body;             /* statements */
    bool from_lib;        /* standard library POU */
    bool used;
    bool uses_return;
    Type *type;           /* FB / program: its instance type */
    Vec syms;             /* Sym of its variables, in declaration order */
    Vec calls;            /* functions it calls (Pou*) */
    Sym *en, *eno;        /* its EN input and ENO output, once a call or a body uses them */
};

typedef struct TypeDecl { char *name, *uname; Loc loc; TypeSpec *spec; Node *init; } TypeDecl;

typedef struct Task {
    char *name, *uname; Loc loc;
    Node *interval, *priority, *single;
    int64_t interval_ns;
} Task;

typedef struct ProgInst {
    char *name, *uname; Loc loc;
    char *task, *pou; Loc taskloc, pouloc;
    Task *t; Pou *p;
    bool retain;
} ProgInst;

typedef struct Resource {
    char *name, *uname; Loc loc;
    Vec globals;   /* VarDecl */
    Vec tasks;     /* Task */
    Vec progs;     /* ProgInst */
    Vec gsyms;
    bool single;   /* tasks and programs right in the CONFIGURATION (no RESOURCE) */
} Resource;

typedef struct Config {
    char *name, *uname; Loc loc;
    Vec globals;
    Vec resources;
    Vec gsyms;
} Config;

/* A top-level declaration as written: a POU, one type of a TYPE block, a
** CONFIGURATION or a top-level pragma, with its tokens first..last. */
typedef enum { IT_POU, IT_TYPE, IT_CONFIG, IT_PRAGMA } ItemKind;
typedef struct Item {
    ItemKind kind;
    void *decl;           /* Pou*, TypeDecl*, Config*, Token* */
    const char *uname;    /* the declared name (NULL for a pragma) */
    Vec names;            /* further names it declares: an enumeration's values */
    Token *first, *last;
    bool library;         /* from a library file (stc -L) */
    bool dropped;         /* a library declaration the program replaces */
    int index;            /* join.c's number for it */
} Item;

typedef struct Unit {
    Vec types;     /* TypeDecl */
    Vec pous;      /* Pou */
    Vec configs;   /* Config */
    Vec pragmas;   /* Token*: top-level {{ }} text */
    Vec items;     /* Item*: every top-level declaration of the input files, in order */
    bool library;  /* parse_unit is reading a library file (stc -L) */
} Unit;

void parse_unit(Unit *u, const Source *src, bool from_lib);
/* for il.c: one operand (a unary expression), or a call's arguments after '(' */
Node *parse_il_operand(Token *toks, int n, int *i);
void parse_il_call_args(Token *toks, int n, int *i, Node *call);
/* for sfc.c: an expression; statements up to an END_xxx */
Node *parse_expr_at(Token *toks, int n, int *i);
void parse_stmts_at(Token *toks, int n, int *i, Vec *out);

/* ---- Instruction List bodies (il.c) ---- */
bool il_body_starts(Token *toks, int n, int i);
int il_body(Token *toks, int n, int i, Pou *pou, Unit *u);   /* lowers into pou->body; returns the next token */
/* an SFC action (into out) or transition (*cr: the condition); labels get prefix */
int il_lower(Token *toks, int n, int i, Pou *pou, Unit *u, Vec *out, const char *prefix, Node **cr);

/* ---- Sequential Function Chart bodies (sfc.c) ---- */
bool sfc_body_starts(Token *toks, int n, int i);
int sfc_body(Token *toks, int n, int i, Pou *pou, Unit *u);  /* lowers into pou->body; returns the next token */

/* ---- semantic types (sema.c) ---- */
typedef enum {
    T_BOOL, T_SINT, T_INT, T_DINT, T_LINT, T_USINT, T_UINT, T_UDINT, T_ULINT,
    T_BYTE, T_WORD, T_DWORD, T_LWORD, T_REAL, T_LREAL,
    T_TIME, T_DATE, T_TOD, T_DT, T_STRING,
    T_ENUM, T_STRUCT, T_ARRAY, T_FB,
    T_LITINT, T_LITREAL,  /* untyped literals before the context gives a type */
    T_VOID, T_ERROR,
    T__COUNT
} TypeKind;

typedef struct Field { char *name, *uname; Type *type; Node *init; Loc loc; } Field;
typedef struct Dim { int64_t lo, hi; } Dim;

struct Type {
    TypeKind kind;
    char *name;       /* IEC name, upper-case */
    char *cname;      /* C type name */
    Type *alias;      /* named alias: the type it stands for */
    Type *base;       /* subrange: the integer type it narrows */
    bool subrange; int64_t lo, hi;
    Vec fields;       /* T_STRUCT: Field* ; T_ENUM: char* value names (upper) */
    Type *elem; Dim dims[8]; int ndims; int64_t count;   /* T_ARRAY */
    Pou *pou;         /* T_FB (and programs) */
    Node *init;       /* default initial value of a named derived type */
    bool emitted;
};

typedef enum { SK_VAR, SK_ENUMVAL, SK_POU, SK_TYPE } SymKind;

struct Sym {
    SymKind kind;
    char *name, *uname;
    Loc loc;
    Type *type;
    VarDecl *decl;
    VarClass cls;
    bool constant, retain;
    bool is_global;       /* configuration or resource global */
    char *gcname;         /* C storage name of a global */
    bool pointer;         /* stored as a pointer: in-out, external, located */
    int enum_index;
    Pou *pou;
    bool in_function;     /* variable of a FUNCTION: C local or parameter */
    bool is_result;       /* the function's return variable */
    bool loop_locked;     /* FOR control variable inside its loop */
    bool implicit;        /* EN / ENO nobody declared: never a positional argument */
    bool warned_outside;  /* an internal variable used from outside: said once */
};

extern Type *ty_prim[T__COUNT];
bool is_int(const Type *t);       /* ANY_INT, literal included */
bool is_signed_int(const Type *t);
bool is_real(const Type *t);
bool is_bit(const Type *t);       /* ANY_BIT except BOOL */
bool is_num(const Type *t);
int type_bits(const Type *t);
const char *type_name(const Type *t);

void sema(Unit *u);

/* ---- code generation (codegen.c) ---- */
int codegen(Unit *u, const char *outdir);   /* outdir NULL: generate, write nothing */

/* ---- the project's library and the program's order (join.c) ---- */
/* A POU or type of a user file that a library file (stc -L) also
** declares replaces the library's: silently when both read the same token
** for token, else with a warning naming both places. Library files are
** parsed with Unit.library set. */
void replace_library(Unit *u);
/* Write the kept declarations as one ST file in which every declaration
** precedes its uses (for compilers that read one file in order, as iec2c),
** and a line map: "FIRST LAST FROM FILE" per piece (lines FIRST..LAST of
** out come from FILE's lines FROM...). 0 on success. */
int stc_join_files(const Source *srcs, int nsrcs, int nlib, const char *out, const char *map);

/* ---- the whole pipeline (compile.c): 0 on success, 1 after errors ---- */
int stc_compile(const Source *src, const char *outdir);
/* Several files, one program: declarations of each are visible in all. */
int stc_compile_files(const Source *srcs, int nsrcs, const char *outdir);
/* The same, the first nlib files being the project's library (stc -L). */
int stc_compile_lib(const Source *srcs, int nsrcs, int nlib, const char *outdir);

Type *canon(Type *t);              /* through aliases and subranges */

/* the standard function blocks, in ST (stdlib.c) */
extern const char stdlib_st[];

/* builtin function ids, Node.builtin */
enum {
    B_NONE, B_CONV, B_TRUNC, B_ABS, B_SQRT, B_LN, B_LOG, B_EXP, B_SIN, B_COS, B_TAN,
    B_ASIN, B_ACOS, B_ATAN, B_EXPT, B_SEL, B_MAX, B_MIN, B_LIMIT, B_MUX, B_MOVE,
    B_SHL, B_SHR, B_ROL, B_ROR, B_LEN,
    B_OP,       /* ADD, SUB, ..., GT, ..., NOT: Node.opx holds the operator expression */
    B_DIV,      /* DIV: like '/', and ENO is FALSE on a zero divisor */
    B_CONCAT,
    B_LIB,      /* a function of fixed signature (time, string): Node.libfn is its C helper */
    B_TO_BCD,   /* <U>_TO_BCD[_<B>] */
    B_FROM_BCD, /* [<B>_]BCD_TO_<U> */
};

#endif
