/* IEC 61131-3 elementary types, with matiec's names and widths. */
#ifndef IEC_TYPES_H
#define IEC_TYPES_H

#include <stdint.h>

typedef uint8_t  BOOL;
typedef int8_t   SINT;
typedef int16_t  INT;
typedef int32_t  DINT;
typedef int64_t  LINT;
typedef uint8_t  USINT;
typedef uint16_t UINT;
typedef uint32_t UDINT;
typedef uint64_t ULINT;
typedef uint8_t  BYTE;
typedef uint16_t WORD;
typedef uint32_t DWORD;
typedef uint64_t LWORD;
typedef float    REAL;
typedef double   LREAL;

/* TIME, DATE, TOD, DT: seconds and nanoseconds, tv_nsec in [0, 1e9). */
typedef struct { long tv_sec; long tv_nsec; } IEC_TIMESPEC;
typedef IEC_TIMESPEC TIME;
typedef IEC_TIMESPEC DATE;
typedef IEC_TIMESPEC TOD;
typedef IEC_TIMESPEC DT;
typedef IEC_TIMESPEC IEC_TIME;

#define STR_MAX_LEN 126
typedef struct { uint8_t len; uint8_t body[STR_MAX_LEN]; } STRING;

/* matiec spells these IEC_<TYPE> too */
typedef BOOL IEC_BOOL; typedef SINT IEC_SINT; typedef INT IEC_INT; typedef DINT IEC_DINT;
typedef LINT IEC_LINT; typedef USINT IEC_USINT; typedef UINT IEC_UINT; typedef UDINT IEC_UDINT;
typedef ULINT IEC_ULINT; typedef BYTE IEC_BYTE; typedef WORD IEC_WORD; typedef DWORD IEC_DWORD;
typedef LWORD IEC_LWORD; typedef REAL IEC_REAL; typedef LREAL IEC_LREAL; typedef STRING IEC_STRING;

#endif
