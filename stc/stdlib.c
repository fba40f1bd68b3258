/* The IEC 61131-3 standard function blocks, and the further blocks matiec
** ships (SEMA, HYSTERESIS, INTEGRAL, DERIVATIVE, PID, RAMP, RTC), written in
** Structured Text and compiled with every program (only those it uses reach
** the C output).
** Counters stop at PV (up) and 0 (down), as matiec's do; timers read the
** PLC clock __CURRENT_TIME through an embedded-C line. */
#include "stc.h"

#define COUNTERS(SUFFIX, T)                                                   \
"FUNCTION_BLOCK CTU" #SUFFIX "\n"                                             \
"  VAR_INPUT CU, R : BOOL; PV : " #T "; END_VAR\n"                            \
"  VAR_OUTPUT Q : BOOL; CV : " #T "; END_VAR\n"                               \
"  VAR EDGE : R_TRIG; END_VAR\n"                                              \
"  EDGE(CLK := CU);\n"                                                        \
"  IF R THEN CV := 0;\n"                                                      \
"  ELSIF EDGE.Q AND CV < PV THEN CV := CV + 1;\n"                             \
"  END_IF;\n"                                                                 \
"  Q := CV >= PV;\n"                                                          \
"END_FUNCTION_BLOCK\n"                                                        \
"FUNCTION_BLOCK CTD" #SUFFIX "\n"                                             \
"  VAR_INPUT CD, LD : BOOL; PV : " #T "; END_VAR\n"                           \
"  VAR_OUTPUT Q : BOOL; CV : " #T "; END_VAR\n"                               \
"  VAR EDGE : R_TRIG; END_VAR\n"                                              \
"  EDGE(CLK := CD);\n"                                                        \
"  IF LD THEN CV := PV;\n"                                                    \
"  ELSIF EDGE.Q AND CV > 0 THEN CV := CV - 1;\n"                              \
"  END_IF;\n"                                                                 \
"  Q := CV <= 0;\n"                                                           \
"END_FUNCTION_BLOCK\n"                                                        \
"FUNCTION_BLOCK CTUD" #SUFFIX "\n"                                            \
"  VAR_INPUT CU, CD, R, LD : BOOL; PV : " #T "; END_VAR\n"                    \
"  VAR_OUTPUT QU, QD : BOOL; CV : " #T "; END_VAR\n"                          \
"  VAR UP, DOWN : R_TRIG; END_VAR\n"                                          \
"  UP(CLK := CU);\n"                                                          \
"  DOWN(CLK := CD);\n"                                                        \
"  IF R THEN CV := 0;\n"                                                      \
"  ELSIF LD THEN CV := PV;\n"                                                 \
"  ELSIF UP.Q AND NOT DOWN.Q AND CV < PV THEN CV := CV + 1;\n"                \
"  ELSIF DOWN.Q AND NOT UP.Q AND CV > 0 THEN CV := CV - 1;\n"                 \
"  END_IF;\n"                                                                 \
"  QU := CV >= PV;\n"                                                         \
"  QD := CV <= 0;\n"                                                          \
"END_FUNCTION_BLOCK\n"

const char stdlib_st[] =
"FUNCTION_BLOCK R_TRIG\n"
"  VAR_INPUT CLK : BOOL; END_VAR\n"
"  VAR_OUTPUT Q : BOOL; END_VAR\n"
"  VAR M : BOOL; END_VAR\n"
"  Q := CLK AND NOT M;\n"
"  M := CLK;\n"
"END_FUNCTION_BLOCK\n"
/* F_TRIG as IEC 61131-3 (2nd ed., table 35) writes it, and matiec: M holds
** NOT CLK, FALSE at start, so a first call with CLK = FALSE gives Q = TRUE. */
"FUNCTION_BLOCK F_TRIG\n"
"  VAR_INPUT CLK : BOOL; END_VAR\n"
"  VAR_OUTPUT Q : BOOL; END_VAR\n"
"  VAR M : BOOL; END_VAR\n"
"  Q := NOT CLK AND NOT M;\n"
"  M := NOT CLK;\n"
"END_FUNCTION_BLOCK\n"
"FUNCTION_BLOCK SR\n"
"  VAR_INPUT S1, R : BOOL; END_VAR\n"
"  VAR_OUTPUT Q1 : BOOL; END_VAR\n"
"  Q1 := S1 OR (NOT R AND Q1);\n"
"END_FUNCTION_BLOCK\n"
"FUNCTION_BLOCK RS\n"
"  VAR_INPUT S, R1 : BOOL; END_VAR\n"
"  VAR_OUTPUT Q1 : BOOL; END_VAR\n"
"  Q1 := NOT R1 AND (S OR Q1);\n"
"END_FUNCTION_BLOCK\n"
/* The counters for each PV type matiec has: CTU (INT), CTU_DINT, CTU_LINT,
** CTU_UDINT, CTU_ULINT, and the same for CTD and CTUD. */
COUNTERS(, INT) COUNTERS(_DINT, DINT) COUNTERS(_LINT, LINT) COUNTERS(_UDINT, UDINT) COUNTERS(_ULINT, ULINT)
/* TON: Q rises PT after IN rose and IN is still TRUE; ET counts up to PT. */
"FUNCTION_BLOCK TON\n"
"  VAR_INPUT IN : BOOL; PT : TIME; END_VAR\n"
"  VAR_OUTPUT Q : BOOL; ET : TIME; END_VAR\n"
"  VAR RUNNING : BOOL; START : TIME; NOW : TIME; END_VAR\n"
"  {{ SetFbVar(NOW, __CURRENT_TIME); }}\n"
"  IF NOT IN THEN\n"
"    RUNNING := FALSE; Q := FALSE; ET := T#0s;\n"
"  ELSE\n"
"    IF NOT RUNNING THEN RUNNING := TRUE; START := NOW; END_IF;\n"
"    ET := NOW - START;\n"
"    IF ET >= PT THEN ET := PT; Q := TRUE; ELSE Q := FALSE; END_IF;\n"
"  END_IF;\n"
"END_FUNCTION_BLOCK\n"
/* TOF: Q follows IN up at once, and falls PT after IN fell. */
"FUNCTION_BLOCK TOF\n"
"  VAR_INPUT IN : BOOL; PT : TIME; END_VAR\n"
"  VAR_OUTPUT Q : BOOL; ET : TIME; END_VAR\n"
"  VAR RUNNING : BOOL; START : TIME; NOW : TIME; END_VAR\n"
"  {{ SetFbVar(NOW, __CURRENT_TIME); }}\n"
"  IF IN THEN\n"
"    RUNNING := FALSE; Q := TRUE; ET := T#0s;\n"
"  ELSIF Q THEN\n"
"    IF NOT RUNNING THEN RUNNING := TRUE; START := NOW; END_IF;\n"
"    ET := NOW - START;\n"
"    IF ET >= PT THEN ET := PT; Q := FALSE; RUNNING := FALSE; END_IF;\n"
"  END_IF;\n"
"END_FUNCTION_BLOCK\n"
/* TP: a pulse of length PT on a rising IN; not retriggerable while it runs. */
"FUNCTION_BLOCK TP\n"
"  VAR_INPUT IN : BOOL; PT : TIME; END_VAR\n"
"  VAR_OUTPUT Q : BOOL; ET : TIME; END_VAR\n"
"  VAR PREV : BOOL; START : TIME; NOW : TIME; END_VAR\n"
"  {{ SetFbVar(NOW, __CURRENT_TIME); }}\n"
"  IF NOT Q AND IN AND NOT PREV AND ET = T#0s THEN\n"
"    Q := TRUE; START := NOW;\n"
"  END_IF;\n"
"  IF Q THEN\n"
"    ET := NOW - START;\n"
"    IF ET >= PT THEN ET := PT; Q := FALSE; END_IF;\n"
"  END_IF;\n"
"  IF NOT Q AND NOT IN THEN ET := T#0s; END_IF;\n"
"  PREV := IN;\n"
"END_FUNCTION_BLOCK\n"
/* The blocks of IEC 61131-3 (2nd ed.) annex F that matiec ships in ST, with
** their meaning there. SEMA: CLAIM takes, RELEASE frees, BUSY tells. */
"FUNCTION_BLOCK SEMA\n"
"  VAR_INPUT CLAIM, RELEASE : BOOL; END_VAR\n"
"  VAR_OUTPUT BUSY : BOOL; END_VAR\n"
"  VAR HELD : BOOL; END_VAR\n"
"  HELD := CLAIM OR (HELD AND NOT RELEASE);\n"
"  BUSY := HELD;\n"
"END_FUNCTION_BLOCK\n"
/* HYSTERESIS: Q rises when XIN1 > XIN2 + EPS, falls when XIN1 < XIN2 - EPS. */
"FUNCTION_BLOCK HYSTERESIS\n"
"  VAR_INPUT XIN1, XIN2, EPS : REAL; END_VAR\n"
"  VAR_OUTPUT Q : BOOL; END_VAR\n"
"  IF Q THEN\n"
"    IF XIN1 < XIN2 - EPS THEN Q := FALSE; END_IF;\n"
"  ELSIF XIN1 > XIN2 + EPS THEN Q := TRUE;\n"
"  END_IF;\n"
"END_FUNCTION_BLOCK\n"
/* INTEGRAL: XOUT += XIN * CYCLE (in seconds) while RUN; R1 loads X0. */
"FUNCTION_BLOCK INTEGRAL\n"
"  VAR_INPUT RUN, R1 : BOOL; XIN, X0 : REAL; CYCLE : TIME; END_VAR\n"
"  VAR_OUTPUT Q : BOOL; XOUT : REAL; END_VAR\n"
"  Q := NOT R1;\n"
"  IF R1 THEN XOUT := X0;\n"
"  ELSIF RUN THEN XOUT := XOUT + XIN * TIME_TO_REAL(CYCLE);\n"
"  END_IF;\n"
"END_FUNCTION_BLOCK\n"
/* DERIVATIVE: the standard's four-point difference over the last samples,
** (3 (x0 - x3) + x1 - x2) / (10 CYCLE); RUN = FALSE gives 0 and loads them. */
"FUNCTION_BLOCK DERIVATIVE\n"
"  VAR_INPUT RUN : BOOL; XIN : REAL; CYCLE : TIME; END_VAR\n"
"  VAR_OUTPUT XOUT : REAL; END_VAR\n"
"  VAR X1, X2, X3 : REAL; END_VAR\n"
"  IF RUN THEN\n"
"    XOUT := (3.0 * (XIN - X3) + X1 - X2) / (10.0 * TIME_TO_REAL(CYCLE));\n"
"    X3 := X2; X2 := X1; X1 := XIN;\n"
"  ELSE\n"
"    XOUT := 0.0; X1 := XIN; X2 := XIN; X3 := XIN;\n"
"  END_IF;\n"
"END_FUNCTION_BLOCK\n"
/* PID: XOUT = KP (e + integral(e)/TR + TD de/dt), e = PV - SP; in manual
** (AUTO = FALSE) the integral is preset so that XOUT = X0. */
"FUNCTION_BLOCK PID\n"
"  VAR_INPUT AUTO : BOOL; PV, SP, X0, KP, TR, TD : REAL; CYCLE : TIME; END_VAR\n"
"  VAR_OUTPUT XOUT : REAL; END_VAR\n"
"  VAR ERROR : REAL; ITERM : INTEGRAL; DTERM : DERIVATIVE; END_VAR\n"
"  ERROR := PV - SP;\n"
"  ITERM(RUN := AUTO, R1 := NOT AUTO, XIN := ERROR, X0 := TR * (X0 - ERROR), CYCLE := CYCLE);\n"
"  DTERM(RUN := AUTO, XIN := ERROR, CYCLE := CYCLE);\n"
"  XOUT := KP * (ERROR + ITERM.XOUT / TR + DTERM.XOUT * TD);\n"
"END_FUNCTION_BLOCK\n"
/* RAMP: RUN = FALSE tracks X0; RUN = TRUE goes linearly from there to X1
** in TR, one CYCLE per call, BUSY while on the way. */
"FUNCTION_BLOCK RAMP\n"
"  VAR_INPUT RUN : BOOL; X0, X1 : REAL; TR, CYCLE : TIME; END_VAR\n"
"  VAR_OUTPUT BUSY : BOOL; XOUT : REAL; END_VAR\n"
"  VAR XI : REAL; ELAPSED : TIME; END_VAR\n"
"  BUSY := RUN;\n"
"  IF RUN THEN\n"
"    IF ELAPSED >= TR THEN BUSY := FALSE; XOUT := X1;\n"
"    ELSE\n"
"      XOUT := XI + (X1 - XI) * TIME_TO_REAL(ELAPSED) / TIME_TO_REAL(TR);\n"
"      ELAPSED := ELAPSED + CYCLE;\n"
"    END_IF;\n"
"  ELSE\n"
"    XOUT := X0; XI := X0; ELAPSED := T#0s;\n"
"  END_IF;\n"
"END_FUNCTION_BLOCK\n"
/* RTC: CDT is the PLC clock as a date and time, or, while IN, PDT (taken on
** IN's rising edge) plus the time since; Q copies IN. */
"FUNCTION_BLOCK RTC\n"
"  VAR_INPUT IN : BOOL; PDT : DT; END_VAR\n"
"  VAR_OUTPUT Q : BOOL; CDT : DT; END_VAR\n"
"  VAR PREV_IN : BOOL; OFFSET : TIME; NOW : DT; END_VAR\n"
"  {{ SetFbVar(NOW, __CURRENT_TIME); }}\n"
"  IF IN THEN\n"
"    IF NOT PREV_IN THEN OFFSET := PDT - NOW; END_IF;\n"
"    CDT := NOW + OFFSET;\n"
"  ELSE\n"
"    CDT := NOW;\n"
"  END_IF;\n"
"  Q := IN;\n"
"  PREV_IN := IN;\n"
"END_FUNCTION_BLOCK\n";
