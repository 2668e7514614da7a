"""Parameters and expressions, with LinuxCNC (rs274ngc) semantics.

Expressions are the nested tuples the parser builds (see
ncpp.program.blocks): ("num", v) ("param", key) ("neg", x) ("pos", x)
("bin", op, a, b) ("call", NAME, x) ("atan2", a, b) ("exists", param).
Angles are in degrees, comparisons use rs274ngc's 0.0001 tolerance, MOD
is never negative, ROUND rounds half away from zero.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable

from ncpp.motion.endless import ABSENT, Journal, exact

# rs274ngc: numbered parameters 1..RS274NGC_MAX_PARAMETERS-1 (#0 is Fanuc's null, read as 0)
MAX_PARAMETER = 5601
SUBROUTINE_PARAMETERS = 30  # #1..#30: a subroutine's arguments, local to each call
MACRO_LOCALS = 33  # Fanuc: #1..#33, a new level of them for each G65 macro call
EQUAL_TOLERANCE = 0.0001


class ExpressionError(Exception):
    """A bad expression (divide by zero, undefined parameter...); the caller adds the location."""


class OutOfScope(Exception):
    """Something the interpreter does not evaluate (HAL pins, INI values, machine state)."""


def round_half_away(x: float) -> float:
    """rs274ngc's ROUND: half away from zero."""
    return float(math.floor(x + 0.5)) if x >= 0 else -float(math.floor(-x + 0.5))


def _acos(x: float) -> float:
    if not -1.0 <= x <= 1.0:
        raise ExpressionError("Argument to acos out of range")
    return math.degrees(math.acos(x))


def _asin(x: float) -> float:
    if not -1.0 <= x <= 1.0:
        raise ExpressionError("Argument to asin out of range")
    return math.degrees(math.asin(x))


def _ln(x: float) -> float:
    if x <= 0.0:
        raise ExpressionError("Zero or negative argument to ln")
    return math.log(x)


def _sqrt(x: float) -> float:
    if x < 0.0:
        raise ExpressionError("Negative argument to sqrt")
    return math.sqrt(x)


def _bcd(x: float) -> float:  # Fanuc: binary -> binary-coded decimal
    return float(int(str(int(x)), 16))


def _bin(x: float) -> float:  # Fanuc: binary-coded decimal -> binary
    return float(int(format(int(x), "x")))


FUNCTIONS: dict[str, Callable[[float], float]] = {
    "ABS": abs,
    "ACOS": _acos,
    "ASIN": _asin,
    "COS": lambda x: math.cos(math.radians(x)),
    "EXP": math.exp,
    "FIX": lambda x: float(math.floor(x)),
    "FUP": lambda x: float(math.ceil(x)),
    "ROUND": round_half_away,
    "LN": _ln,
    "SIN": lambda x: math.sin(math.radians(x)),
    "SQRT": _sqrt,
    "TAN": lambda x: math.tan(math.radians(x)),
    "BIN": _bin,
    "BCD": _bcd,
}


def _divide(a: float, b: float) -> float:
    if b == 0.0:
        raise ExpressionError("Attempt to divide by zero")
    return a / b


def _modulo(a: float, b: float) -> float:
    if b == 0.0:
        raise ExpressionError("Attempt to divide by zero")
    r = math.fmod(a, b)
    return r + abs(b) if r < 0.0 else r


def _power(a: float, b: float) -> float:
    if a < 0.0 and b != math.floor(b):
        raise ExpressionError("Attempt to raise negative to non-integer power")
    if a == 0.0 and b < 0.0:  # 1 / 0**|b|
        raise ExpressionError("Attempt to divide by zero (zero to a negative power)")
    return math.pow(a, b)


OPERATORS: dict[str, Callable[[float, float], float]] = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": _divide,
    "MOD": _modulo,
    "**": _power,
    "EQ": lambda a, b: float(abs(a - b) < EQUAL_TOLERANCE),
    "NE": lambda a, b: float(abs(a - b) >= EQUAL_TOLERANCE),
    "GT": lambda a, b: float(a > b),
    "GE": lambda a, b: float(a >= b),
    "LT": lambda a, b: float(a < b),
    "LE": lambda a, b: float(a <= b),
    "AND": lambda a, b: float(a != 0.0 and b != 0.0),
    "OR": lambda a, b: float(a != 0.0 or b != 0.0),
    "XOR": lambda a, b: float((a != 0.0) != (b != 0.0)),
}
LOGIC = frozenset(("AND", "OR", "XOR"))
# Haas's logical operators work on the bits of the values' integer parts (Haas Mill Operator's Manual
# 96-8000, "Macros", "Logical Operators": `#1=1.0; #2=2.0; #3=#1 OR #2;` leaves 3.0 in #3)
BITWISE: dict[str, Callable[[int, int], int]] = {
    "AND": lambda a, b: a & b,
    "OR": lambda a, b: a | b,
    "XOR": lambda a, b: a ^ b,
}


class Parameters:
    """Numbered (`#1`) and named (`#<name>`) parameters.

    `system` answers reads of LinuxCNC's predefined read-only names
    (`#<_x>`, `#<_metric>`...) from the interpreter's state; numbered
    parameters the interpreter keeps in machine state (work offsets, G28
    positions, current position: 5161-5390, 5400-5428) are out of scope,
    read or written, because their values depend on the control's own files
    and units, but for the reads `control` answers (the tool in the spindle's,
    where ncpp knows it; it may raise OutOfScope saying why it does not).
    """

    def __init__(
        self,
        system: Callable[[str], float | None] | None = None,
        fanuc_system: Callable[[int], float | None] | None = None,
        control: Callable[[int], float | None] | None = None,
    ):
        self.numbered: dict[int, float] = {}
        self.named: dict[str, float] = {
            "_value": 0.0,
            "_value_returned": 0.0,
        }  # what the last subroutine returned
        self.system = system
        self._callers: list[
            tuple[list[float] | None, dict[str, float], set[int]]
        ] = []  # per call level: the caller's #1..#30 (#1..#33), local names and vacant numbers
        # Fanuc's vacant (<null>) variables: #0, a G65 argument not given, `#i = #0` (Fanuc 16i/18i
        # operator's manual B-63684EN, "Custom macro", Variables: a vacant variable reads as 0 in
        # arithmetic, differs from 0 in EQ and NE, and leaves out the address it is the value of)
        self.vacant: set[int] = set()
        self.fanuc = False  # a Fanuc program: #1000 and up are the control's system variables
        self.fanuc_system = fanuc_system  # those the interpreter knows (None: not known)
        self.control = control  # LinuxCNC's machine-state parameters the interpreter knows (None: not known)
        self.kept: frozenset[int] = frozenset()  # the control's common variables, set before the program
        # AND OR XOR: rs274ngc's truth values ("logical"), Haas's bits ("bitwise", `BITWISE`), or a Fanuc
        # control's, followed where both values are 0 or 1, whose results agree then ("binary")
        self.logic = "logical"
        self.unknown: dict[int | str, str] = {}  # parameters set from a value ncpp cannot know: whence
        self.journal: Journal | None = None  # the writes a loop's check follows (`endless.py`)

    def entry(self, key: Hashable) -> object:
        """A parameter's value as the journal compares it (`exact`; a number's vacancy with it)."""
        if type(key) is int:
            value = self.numbered.get(key, ABSENT)
            if type(value) is float and value != 0.0:  # (the common case, as `exact` has it)
                return value, key in self.vacant
            return (ABSENT if value is ABSENT else exact(value)), key in self.vacant
        value = self.named.get(key, ABSENT)  # type: ignore[call-overload]
        return ABSENT if value is ABSENT else exact(value)

    def _note(self, keys) -> None:
        """Parameters about to change, for the journal (when a loop's check follows them)."""
        journal = self.journal
        if journal is not None:
            for key in keys:
                if key not in journal.before:
                    journal.before[key] = self.entry(key)

    def start_fanuc(self) -> None:
        """A Fanuc macro program starts: its local variables #1-#33 vacant, and #1000 and up the
        control's system variables (the machine's position, offsets, alarms), which ncpp does not
        know but for the messages (#3000, #3006, the interpreter's) (Fanuc 16i/18i operator's
        manual, "Custom macro", Variables: local variables are vacant at the start)."""
        self.fanuc = True
        self.vacant.update(range(1, MACRO_LOCALS + 1))

    def enter(self, arguments: list[float] | None) -> None:
        """A subroutine call: #1..#30 are its arguments (0 past the last; None, a Fanuc
        M98 call: the caller's, shared), and names without a leading underscore are
        its own (the caller's come back at `leave`)."""
        saved = (
            None
            if arguments is None
            else [self.numbered.get(n, 0.0) for n in range(1, SUBROUTINE_PARAMETERS + 1)]
        )
        local = {k: v for k, v in self.named.items() if not k.startswith("_")}
        # (an M98 call shares the caller's #1..: only a call with arguments changes them)
        self._note((*local, *(() if arguments is None else range(1, SUBROUTINE_PARAMETERS + 1))))
        for k in local:
            del self.named[k]
        self._callers.append((saved, local, set(self.vacant)))
        if arguments is not None:
            for n in range(1, SUBROUTINE_PARAMETERS + 1):
                self.numbered[n] = arguments[n - 1] if n <= len(arguments) else 0.0
                self.vacant.discard(n)

    def enter_macro(self, arguments: dict[int, float]) -> None:
        """A Fanuc G65 macro call: a new level of #1..#33, those `arguments` names set, the rest
        vacant (the caller's come back at `leave`)."""
        self._note(range(1, MACRO_LOCALS + 1))
        self._callers.append(
            ([self.numbered.get(n, 0.0) for n in range(1, MACRO_LOCALS + 1)], {}, set(self.vacant))
        )
        for n in range(1, MACRO_LOCALS + 1):
            self.numbered[n] = arguments.get(n, 0.0)
        self.vacant.difference_update(arguments)
        self.vacant.update(n for n in range(1, MACRO_LOCALS + 1) if n not in arguments)

    def leave(self, value: float | None) -> None:
        """The subroutine returns (`value`: what its return or endsub gave, if anything)."""
        saved, local, vacant = self._callers.pop()
        if self.journal is not None:  # (#1.. come back only where the call saved them)
            self._note((*self.named, *local, *(() if saved is None else range(1, MACRO_LOCALS + 1))))
        for k in [k for k in self.named if not k.startswith("_")]:
            del self.named[k]
        self.named.update(local)
        if saved is not None:
            self.numbered.update(zip(range(1, len(saved) + 1), saved))
            if self.vacant or vacant:  # the caller's locals as they were; what the call did to the others
                self.vacant = {k for k in self.vacant if k > len(saved)} | {
                    k for k in vacant if k <= len(saved)
                }
        self.named["_value"], self.named["_value_returned"] = (0.0, 0.0) if value is None else (value, 1.0)

    def main_level(self) -> tuple[dict[int, float], dict[str, float], frozenset[int]]:
        """Copies of the numbered and named parameters and of the vacant numbers as the main
        program has them: while calls are under way, its own #1.. and local names as the first
        call that took them saved them (`leave` gives them back so)."""
        numbered, named, vacant = dict(self.numbered), dict(self.named), set(self.vacant)
        if not self._callers:
            return numbered, named, frozenset(vacant)
        named = {k: v for k, v in named.items() if k.startswith("_")}
        named.update(self._callers[0][1])
        for saved, _, was_vacant in self._callers:
            if saved is not None:  # (None: an M98 call shares its caller's #1..)
                numbered.update(zip(range(1, len(saved) + 1), saved))
                vacant = {k for k in vacant if k > len(saved)} | {k for k in was_vacant if k <= len(saved)}
                break
        return numbered, named, frozenset(vacant)

    def key(self, key, evaluate: Callable[[tuple], float]) -> int | str:
        if isinstance(key, tuple):  # `#[expr]`, `##1`
            value = evaluate(key[1])
            key = int(round(value))
            if abs(key - value) > EQUAL_TOLERANCE:
                raise ExpressionError("Parameter number out of range")
        if isinstance(key, int):
            # (a Fanuc or Haas control numbers its variables past rs274ngc's last: `read` and `write`
            # take those from #1000 on as its system variables, but for `kept`)
            if not 1 <= key <= MAX_PARAMETER and key != 0 and not (self.fanuc and key > 0):
                raise ExpressionError("Parameter number out of range")
            return key
        return normalise_name(key)

    def set_unknown(self, key: int | str, whence: str) -> None:
        """`key` takes a value ncpp cannot know (a timer's, the machine's): a block that reads it later
        is out of scope for `whence`, one that never does runs on (`#10002 = #3020 - #10000`, a cycle timer
        at a Haas program's start)."""
        self.write(key, 0.0)
        self.unknown[key] = whence

    def is_vacant(self, key: int | str) -> bool:
        """Fanuc's vacant variable: #0, or one the program left vacant (`vacant`)."""
        return key == 0 or key in self.vacant

    def vacate(self, key: int) -> None:
        """`#i = #0` (or another vacant variable): #i is vacant, as Fanuc assigns it."""
        self.write(key, 0.0)
        self.vacant.add(key)

    def read(self, key: int | str) -> float:
        if self.unknown and key in self.unknown:
            raise OutOfScope(self.unknown[key])
        if type(key) is int:
            if key in self.kept:
                value = self.numbered.get(key)
                if value is None:
                    raise OutOfScope(f"#{key}, a variable the control keeps from before the program")
                return value
            if _machine_state(key) or key >= 1000 and self.fanuc:
                lookup = self.fanuc_system if self.fanuc else self.control
                known = lookup(key) if lookup is not None else None
                if known is not None:
                    return known
                raise OutOfScope(f"machine-state parameter #{key}" if not self.fanuc else
                                 f"the control's system variable #{key}")  # fmt: skip
            return self.numbered.get(key, 0.0)  # (a vacant one: 0 in arithmetic, as Fanuc reads it)
        name: str = key  # type: ignore[assignment]  # not an int (`type() is`, for speed, narrows no else)
        value = self.named.get(name)
        if value is not None:
            return value
        if name.startswith("_") and self.system is not None:
            value = self.system(name)
            if value is not None:
                return value
            if name.startswith(("_hal[", "_ini[")) or name in _MACHINE_STATE:
                raise OutOfScope(f"machine-state parameter #<{name}>")
        raise ExpressionError(f"Named parameter #<{name}> not defined")

    def exists(self, key: int | str) -> bool:
        if type(key) is int:
            return True
        name: str = key  # type: ignore[assignment]  # not an int
        system = self.system
        return name in self.named or (
            name.startswith("_") and system is not None and system(name) is not None
        )

    def write(self, key: int | str, value: float) -> None:
        if self.unknown:
            self.unknown.pop(key, None)
        if type(key) is int:
            if (
                _machine_state(key) or key >= 1000 and self.fanuc
            ) and key not in self.kept:  # the control's zeros follow it, in its own units
                raise OutOfScope(f"a write to the machine-state parameter #{key}" if not self.fanuc else
                                 f"a write to the control's system variable #{key}")  # fmt: skip
            journal = self.journal
            if journal is not None and key not in journal.before:
                journal.before[key] = self.entry(key)
            self.numbered[key] = value
            if self.vacant:
                self.vacant.discard(key)
            return
        name: str = key  # type: ignore[assignment]  # not an int
        if name.startswith("_") and self.system is not None and self.system(name) is not None:
            raise ExpressionError(f"Cannot assign to read-only parameter #<{name}>")
        journal = self.journal
        if journal is not None and name not in journal.before:
            journal.before[name] = self.entry(name)
        self.named[name] = value


def _machine_state(key: int) -> bool:
    """Numbered parameters the control keeps: G28/G30 positions, G92, the work offsets
    (5161-5390) and the tool in the spindle (5400-5428)."""
    return 5161 <= key <= 5390 or 5400 <= key <= 5428


# Predefined names whose values live in the control (tool table, spindle, task state).
_MACHINE_STATE = frozenset(
    "_current_tool _current_pocket _selected_tool _selected_pocket _rpm _spindle_on _spindle_cw "
    "_mist _flood _speed_override _feed_override _adaptive_feed _feed_hold _task _call_level "
    "_remap_level _vmajor _vminor _retract_r1 _retract_old_z".split()
)


def normalise_name(name: str) -> str:
    """`<My Var>` -> `myvar`: rs274ngc ignores case and spaces in names."""
    if name.startswith("<"):
        name = name[1:-1]
    return "".join(name.split()).lower()


def evaluate(expr: tuple, params: Parameters) -> float:
    """The value of an expression; raises ExpressionError or OutOfScope."""
    if expr[0] == "num":  # (most expressions are a number)
        value = expr[1]
    else:
        try:
            value = _value(expr, params)
        except OverflowError:  # math.exp, math.pow, ** past the largest float
            raise ExpressionError("Number out of range") from None
    if not math.isfinite(value):  # a sum or product past the largest float, or a number too long
        raise ExpressionError("Number out of range")
    return value


def _value(expr: tuple, params: Parameters) -> float:
    kind = expr[0]
    if kind == "num":
        return expr[1]
    if kind == "param":
        return params.read(params.key(expr[1], lambda e: evaluate(e, params)))
    if kind == "bin":
        op = expr[1]
        if (op == "EQ" or op == "NE") and (vacant(expr[2], params) or vacant(expr[3], params)):
            same = vacant(expr[2], params) and vacant(expr[3], params)  # vacant EQ 0 is false
            return float(same == (op == "EQ"))
        if op in LOGIC and params.logic != "logical":
            return _logic(op, evaluate(expr[2], params), evaluate(expr[3], params), params.logic)
        return OPERATORS[op](evaluate(expr[2], params), evaluate(expr[3], params))
    if kind == "neg":
        return -evaluate(expr[1], params)
    if kind == "pos":
        return evaluate(expr[1], params)
    if kind == "call":
        return FUNCTIONS[expr[1]](evaluate(expr[2], params))
    if kind == "atan2":
        return math.degrees(math.atan2(evaluate(expr[1], params), evaluate(expr[2], params)))
    if kind == "exists":
        target = expr[1]
        return float(params.exists(params.key(target[1], lambda e: evaluate(e, params))))
    raise ExpressionError(f"cannot evaluate {kind!r}")


def _logic(op: str, a: float, b: float, logic: str) -> float:
    """`a op b` for AND, OR, XOR, where they are not rs274ngc's truth values (`Parameters.logic`)."""
    if logic == "bitwise":
        return float(BITWISE[op](math.trunc(a), math.trunc(b)))
    if a not in (0.0, 1.0) or b not in (0.0, 1.0):
        raise OutOfScope(
            f"{_number(a)} {op} {_number(b)} (a logical operation on values other than 0 and 1, whose "
            "result ncpp cites from no Fanuc manual)"
        )
    return OPERATORS[op](a, b)


def _number(value: float) -> str:
    return f"{value:g}"


def vacant(expr: tuple, params: Parameters) -> bool:
    """An expression that is a vacant Fanuc variable itself (`#0`, an argument a G65 call left
    out; `[#1+0]` is 0): EQ and NE tell it from 0, an address it is the value of is left out."""
    return expr[0] == "param" and type(expr[1]) is int and params.is_vacant(expr[1])
