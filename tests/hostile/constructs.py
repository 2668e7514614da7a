"""A seeded generator of programs built from the constructs ncpp follows in each dialect (rigid tap,
Fanuc macro calls and additional offsets, Klartext patterns, cycles and called programs, Sinumerik
subprograms, hole patterns and cycles, cutter compensation in every plane), their words given
values a damaged or hostile program holds: zero, negative, huge, NaN, expressions, left out.

`case(rng, folder)` writes one program (and the files it calls, its variable file or tool table)
under `folder` and returns the `ncpp` arguments that run it; `tests/hostile/fuzz.py` runs them.
"""

from __future__ import annotations

import random
from pathlib import Path

MACHINE = "/work/shared/machines/wide.toml"
NUMBERS = ["1", "5", "-5", "0", "-0", "0.0001", "2.5", "-1000000000", "99999999", "-20", "360", "0.5",
           "3", "1000000000", "0.000000000001", "4", "12", "-1", "7", "1" + "0" * 300]  # fmt: skip
ODD = ["", "nan", "1e9", "inf", "1e308"]


def number(rng: random.Random) -> str:
    return rng.choice(ODD) if rng.random() < 0.05 else rng.choice(NUMBERS)


def _iso_value(rng: random.Random) -> str:
    pick = rng.random()
    if pick < 0.15:
        return rng.choice(["[1/0]", "[#1]", "[#<_x>+1]", "[SQRT[-1]]", "#3", "[1e308*10]", "[2*3]"])
    return number(rng)


def _iso(rng: random.Random) -> tuple[str, list[str]]:
    v = lambda: _iso_value(rng)  # noqa: E731
    lines = ["G21 G90 G17 G94", "T1 M6 G43", "S300 M3", f"G0 X{v()} Y{v()} Z{v()}"]
    pool = [
        lambda: f"G33.1 Z{v()} K{v()}",
        lambda: f"G33.1 Z{v()} K{v()} I{v()}",
        lambda: f"G91 G33.1 Z{v()} K{v()}\nG90",
        lambda: f"G91 G33.1 X{v()} Z{v()} K{v()}",
        lambda: f"G33.1 X{v()} Y{v()} Z{v()} K{v()}",
        lambda: f"G93 G33.1 Z{v()} K{v()} F{v()}\nG94",
        lambda: f"G18 G33.1 Y{v()} K{v()}\nG17",
        lambda: f"G19 G33.1 X{v()} K{v()}\nG17",
        lambda: f"G33.1 Z{v()} K{v()}\nX{v()}\nZ{v()}",
        lambda: f"G33.1 Z{v()}",
        lambda: f"G33.1 K{v()}",
        lambda: f"G33.1 Z-5 K1 P{v()}",
        lambda: f"G33.1 Z-5 K1 R{v()}",
        lambda: f"#1={v()}\nG33.1 Z[#1-1] K[#1/2]",
        lambda: f"o100 repeat [{v()}]\nG33.1 Z{v()} K1\no100 endrepeat",
        lambda: "o101 while [#2 LT 3]\n#2=[#2+1]\nG91 G33.1 Z-1 K1\nG90\no101 endwhile",
        lambda: f"G20\nG33.1 Z{v()} K{v()}\nG21",
        lambda: f"G0 X{v()} Y{v()} Z{v()}",
        lambda: f"G1 X{v()} Y{v()} F{v()}",
        lambda: f"G18 G41 D{v()}\nG1 X{v()} Z{v()} F100\nG1 Z{v()}\nG40\nG17",
        lambda: f"G19 G91 G42 D1\nG1 Y{v()} Z{v()} F100\nG1 Y{v()}\nG40 G90\nG17",
        lambda: f"G91 G41.1 D{v()}\nG1 X{v()} Y{v()} F100\nG1 X{v()}\nG40 G90",
        lambda: f"G10 L2 P{v()} X{v()} Y{v()} Z{v()}",
        lambda: f"G10 L20 P{v()} X{v()}",
        lambda: f"G5{rng.choice('456789')}",
        lambda: f"G43 H{v()}",
        lambda: f"T{v()} M6\nG43 H{v()}",
        lambda: f"G2 X{v()} Y{v()} R{v()} F100",
        lambda: f"G81 X{v()} Y{v()} Z{v()} R{v()} F100\nG80",
        lambda: f"G84 X{v()} Z{v()} R{v()} F100\nG80",
        lambda: f"G18 G98 G83 X{v()} Z{v()} Y{v()} R{v()} Q{v()} F100\nX{v()}\nG80 G17",
        lambda: f"G19 G91 G81 Y{v()} Z{v()} X{v()} R{v()} L{v()} F100\nG90 G80 G17",
        lambda: f"G18 G87 X{v()} Z{v()} Y{v()} R{v()} I{v()} J{v()} K{v()} F100\nG80 G17",
    ]
    lines += [rng.choice(pool)() for _ in range(rng.randint(1, 8))]
    extra = rng.choice([[], ["--expand"], ["--expand-cycles"], ["--expand", "--expand-cycles"]])
    return "\n".join(lines + ["M5", "M2"]) + "\n", extra


def _fanuc(rng: random.Random) -> tuple[str, list[str]]:
    v = lambda: _iso_value(rng)  # noqa: E731
    letters = "ABCIJKDEFHMQRSTUVWXYZ"
    args = lambda: " ".join(f"{rng.choice(letters)}{v()}" for _ in range(rng.randint(0, 14)))  # noqa: E731
    lines = ["%", "O1000", "G21 G90 G17 G94", "T1 M6", "S300 M3", "G0 G43 H1 Z50", "G0 X0 Y0"]
    pool = [
        lambda: f"G65 P9010 {args()}",
        lambda: f"G65 P{v()} {args()}",
        lambda: f"G66 P9010 {args()}\nG0 X{v()} Y{v()}\nG67",
        lambda: f"G66 P9010 {args()}\nX{v()}",
        lambda: f"G54.1 P{v()}",
        lambda: f"G54.1 P{rng.randint(0, 50)}\nG0 X{v()} Y{v()}",
        lambda: f"G154 P{rng.randint(0, 100)}\nG0 X{v()}",
        lambda: f"G10 L2 P{v()} X{v()} Y{v()} Z{v()}",
        lambda: f"G10 L20 P{v()} X{v()}",
        lambda: f"G41 D{v()}\nG1 X{v()} Y{v()} F100\nG1 X{v()} Y{v()}\nG1 X{v()}\nG40 G1 X0 Y0",
        lambda: f"G18 G42 D1\nG1 X{v()} Z{v()} F100\nG1 X{v()}\nG40\nG17",
        lambda: f"G91 G41 D1\nG1 X{v()} Y{v()} F100\nG2 X{v()} Y{v()} R{v()}\nG40 G90",
        lambda: f"M98 P9010 L{v()}",
        lambda: f"M97 P{rng.choice(['9020', v()])} L{v()}",  # (Haas's local call: the program is Haas's)
        lambda: f"#{rng.choice(['1', '7001', '5221', '14001', '100'])}={v()}",
        lambda: f"G0 X{v()} Y{v()} Z{v()}",
    ]
    lines += [rng.choice(pool)() for _ in range(rng.randint(1, 8))]
    body = ["O9010", "#100=#1+#4+#7", "G1 X#24 Y#25 F100", f"G1 Z[#26+{v()}]", "M99"]
    if rng.random() < 0.2:
        body.insert(1, "G65 P9010 A1")
    body = ["N9020 (LOCAL)", f"G91 G1 X{v()} F100", "G90", "M99"] + body
    return "\n".join(lines + ["M30"] + body + ["%"]) + "\n", []


def _heidenhain(rng: random.Random, folder: Path) -> tuple[str, list[str]]:
    n = lambda: number(rng) or "0"  # noqa: E731
    s = lambda: ("+" if not n().startswith("-") else "") + n()  # noqa: E731
    pool = [
        lambda: f"PATTERN DEF ~\n   CIRC1 (X{s()} Y{s()} D{s()} START{s()} NUM{n()} Z{s()})",
        lambda: (
            f"PATTERN DEF ~\n   PAT1 (X{s()} Y{s()} DX{s()} DY{s()} NUMX{n()} NUMY{n()} ROT{s()} "
            f"ROTX{s()} ROTY{s()} Z{s()})"
        ),
        lambda: f"PATTERN DEF ~\n   ROW1 (X{s()} Y{s()} D{s()} NUM{n()} ROT{s()} Z{s()})",
        lambda: f"PATTERN DEF ~\n   POS1 (X{s()} IY{s()} Z{s()})",
        lambda: (
            f"PATTERN DEF ~\n   FRAME1 (X{s()} Y{s()} DX{s()} DY{s()} NUMX{n()} NUMY{n()} ROT+0 "
            "ROTX+0 ROTY+0 Z+0)"
        ),
        lambda: f"PATTERN DEF ~\n   PITCHCIRC1 (X{s()} Y{s()} D{s()} START{s()} STEP{s()} NUM{n()} Z{s()})",
        lambda: "CYCL CALL PAT FMAX M13",
        lambda: "CYCL CALL PAT F" + n(),
        lambda: f"CYCL CALL POS X{s()} Y{s()} Z{s()} FMAX",
        lambda: f"CYCL CALL POS IX{s()} Z{s()} F{n()}",
        lambda: (
            f"CYCL DEF 205 UNIVERSAL PECKING ~\n Q200={s()} ~\n Q201={s()} ~\n Q206={s()} ~\n"
            f" Q202={s()} ~\n Q203={s()} ~\n Q204={s()} ~\n Q212={s()} ~\n Q205={s()} ~\n Q258={s()} ~\n"
            f" Q259={s()} ~\n Q257={s()} ~\n Q256={s()} ~\n Q211={s()} ~\n Q379={s()} ~\n Q253={s()}"
        ),
        lambda: (
            f"CYCL DEF 207 RIGID TAPPING ~\n Q200={s()} ~\n Q201={s()} ~\n Q239={s()} ~\n"
            f" Q203={s()} ~\n Q204={s()}"
        ),
        lambda: f"CYCL DEF 207 RIGID TAPPING ~\n Q200={s()} ~\n Q201={s()}",
        lambda: (
            f"CYCL DEF 200 DRILLING ~\n Q200={s()} ~\n Q201={s()} ~\n Q206={s()} ~\n Q202={s()} ~\n"
            f" Q210=+0 ~\n Q203={s()} ~\n Q204={s()} ~\n Q211=+0"
        ),
        lambda: "L FMAX M99",
        lambda: f"L X{s()} Y{s()} FMAX M99",
        lambda: "CYCL CALL",
        lambda: f"TOOL CALL 1 {rng.choice('XYZ')} S1000",
        lambda: f"L IX{s()} IY{s()} R{rng.choice('LR0')} F100",
        lambda: f"L X{s()} Y{s()} Z{s()} R{rng.choice('LR')} F100\nL IX{s()} IZ{s()}\nL IY{s()}\nL X+0 R0",
        lambda: f"CC X{s()} Y{s()}\nC X{s()} Y{s()} DR{rng.choice('+-')} R{rng.choice('LR0')}",
        lambda: f"CALL PGM {_pgm_name(rng, folder)}",
        lambda: f"CALL LBL 1 REP{n()}",
        lambda: f"Q1 = {n()}",
        lambda: f"FN 9: IF +0 EQU +0 GOTO LBL {rng.choice(['1', '2', '99'])}",
        lambda: "LBL 2\nL IX+1 F100\nCALL LBL 2",
    ]
    body = ["TOOL CALL 1 Z S1000", "L X+0 Y+0 Z+50 R0 FMAX"]
    body += [rng.choice(pool)() for _ in range(rng.randint(1, 8))]
    body += ["L Z+50 R0 FMAX", "M30", "LBL 1", "L IX+1 R0 F100", "LBL 0", "LBL 99"]
    flat = "\n".join(body).split("\n")
    lines = ["0 BEGIN PGM FUZZ MM"] + [
        (f"{k} {t}" if not t.startswith(" ") else t) for k, t in enumerate(flat, 1)
    ]
    lines.append(f"{len(flat) + 1} END PGM FUZZ MM")
    extra = rng.choice([[], ["--expand"], ["--expand-cycles"]])
    return "\n".join(lines) + "\n", ["--subroutine-path", str(folder), *extra]


def _pgm_name(rng: random.Random, folder: Path) -> str:
    return rng.choice(["SUB1", "SUB1.H", "TNC:\\parts\\SUB1.H", "SELF", "BIN", "HUGE", "LOOP", "MISSING",
                       "..\\..\\etc\\passwd", "../subs/SUB1", "SUB 1", '"SUB1"', "", "DIR"])  # fmt: skip


def _sinumerik(rng: random.Random, folder: Path) -> tuple[str, list[str]]:
    n = lambda: number(rng)  # noqa: E731
    pool = [
        lambda: f"L{rng.choice(['100', '0100', '7', '99999999', '0', 'SELF'])} P{n()}",
        lambda: f"L100 P{rng.choice(['1', '2', '0', '1e9', '-1'])}",
        lambda: f"MYSUB({', '.join(n() for _ in range(rng.randint(0, 4)))})",
        lambda: f'MYSUB("abc", {n()})',
        lambda: f"MYSUB({n()}, {n()}) P{n()}",
        lambda: "SELFSUB",
        lambda: f"MISSING({n()})",
        lambda: (
            f"MCALL CYCLE81({n()}, {n()}, {n()}, {n()})\nHOLES1({n()}, {n()}, {n()}, {n()}, {n()}, {n()})"
            "\nMCALL"
        ),
        lambda: (
            f"MCALL CYCLE82(10, 0, 2, {n()}, , {n()})\nHOLES2({n()}, {n()}, {n()}, {n()}, {n()}, {n()})"
            "\nMCALL"
        ),
        lambda: f"MCALL CYCLE85(10, 0, 2, -8, , 0.2, {n()}, {n()})\nHOLES2(0, 0, {n()}, 0, 0, {n()})\nMCALL",
        lambda: f"HOLES1({n()}, {n()}, {n()}, {n()}, {n()}, {n()})",
        lambda: f"CYCLE84({n()}, {n()}, {n()}, {n()}, , {n()}, {n()}, , {n()}, {n()}, {n()}, {n()})",
        lambda: f"CYCLE840({n()}, 0, 2, {n()}, , {n()}, 4, 3, {n()}, , {n()})",
        lambda: f"CYCLE8{rng.choice('56789')}({', '.join(n() for _ in range(rng.randint(0, 11)))})",
        lambda: f"CYCLE81({n()}, {n()}, {n()}, {n()})",
        lambda: f"G{rng.choice(['17', '18', '19'])}",
        lambda: "G91",
        lambda: "G90",
        lambda: (
            f"G4{rng.choice('12')} {rng.choice(['NORM', 'KONT', ''])} D{rng.choice(['1', '0', '2'])}\n"
            f"G1 X{n() or 0} Y{n() or 0} Z{n() or 0} F100\nG1 X{n() or 0} Y{n() or 0}\nG40 G1 X0 Y0"
        ),
        lambda: f"G41 KONT\nG91 G1 X{n() or 0} Z{n() or 0} F100\nG2 X5 Z5 CR=5\nG40 G90",
        lambda: f"G0 X{n() or 0} Y{n() or 0} Z{n() or 0}",
        lambda: f"R1={n() or 0}",
        lambda: (
            f"RA: G1 X{n() or 0} Y{n() or 0}\nG1 Z{n() or 0}\nREPEAT {rng.choice(['RA', 'RB', 'RA RA'])} "
            f"P={n()}"
        ),
        lambda: f"RB: G1 X{n() or 0}\nREPEATB {rng.choice(['RB', 'RA', 'RB RA'])} P={n()}",
        lambda: f"REPEAT RC RD P={n()}\nRC: G1 Y{n() or 0}\nRD: G1 X{n() or 0}",
    ]
    lines = ["G17 G90 G71 G94", "T1 D1", "M6", "G0 X10 Y20 Z50", "G1 F200 S500 M3"]
    lines += [rng.choice(pool)() for _ in range(rng.randint(1, 8))]
    return "\n".join(lines + ["M30"]) + "\n", ["--subroutine-path", str(folder)]


def write_called_files(folder: Path) -> None:
    """The files the generated programs call: good ones, a self-calling one, a binary, a huge one,
    a folder and a symbolic link loop."""
    folder.mkdir(parents=True, exist_ok=True)
    files = {
        "SUB1.H": "0 BEGIN PGM SUB1 MM\n1 L IX+1 IY+2 R0 F100\n2 Q2 = Q1 * 3\n3 END PGM SUB1 MM\n",
        "SELF.H": "0 BEGIN PGM SELF MM\n1 L IX+1 F100\n2 CALL PGM SELF\n3 END PGM SELF MM\n",
        "BIN.H": "\x00\x01\xff\xfe binary \x1b",
        "HUGE.H": "0 BEGIN PGM HUGE MM\n" + "1 L IX+0.001 F100\n" * 200_000 + "2 END PGM HUGE MM\n",
        "L0100.SPF": "%_N_L0100_SPF\nN10 G91 G1 X1 Y2\nN20 G90\nN30 M17\n",
        "L7.SPF": "N10 L7\nM17\n",
        "LSELF.SPF": "LSELF\nM17\n",
        "SELFSUB.SPF": "N10 G91 G1 X1\nSELFSUB\nM17\n",
        "_N_MYSUB_SPF": "PROC MYSUB(REAL A, INT B) DISPLOF\nDEF REAL C=0.4\nN10 G1 X=A Y=B+C\nN20 R1=A*2\n"
        "N30 RET\n",
    }
    for name, text in files.items():
        (folder / name).write_bytes(text.encode("latin-1"))
    (folder / "DIR.H").mkdir(exist_ok=True)
    for name, target in (("LOOP.H", "LOOP2.H"), ("LOOP2.H", "LOOP.H")):
        if not (folder / name).is_symlink():
            (folder / name).symlink_to(target)


def _control_files(rng: random.Random, folder: Path, n: int) -> list[str]:
    """A tool table and a parameter file with odd entries (lengths, diameters, pockets, Fanuc's
    additional offsets at #7001...)."""
    tools = folder / f"tool{n}.tbl"
    tools.write_text("".join(
        f"T{rng.choice(['1', '2', '5', '0', '99999999'])} P{rng.choice(['1', '0', '-1', '7'])} "
        f"Z{number(rng)} D{number(rng)}{rng.choice(['', ' X1 Y-2', ' ;comment', ' (x'])}\n"
        for _ in range(rng.randint(0, 4))
    ))  # fmt: skip
    params = folder / f"var{n}.var"
    keys = ["5221", "5222", "5223", "5220", "7001", "7002", "7003", "7021", "14001", "14002", "5211"]
    params.write_text(
        "".join(f"{rng.choice(keys)}\t{number(rng) or '0'}\n" for _ in range(rng.randint(0, 8)))
    )
    return ["--tool-table", str(tools), "--var-file", str(params)]


def case(rng: random.Random, folder: Path, n: int) -> list[str]:
    """One generated program written to `folder` and the `ncpp` arguments that run it."""
    subs = folder / "subs"
    kind = rng.choice(["iso", "fanuc", "heidenhain", "sinumerik"])
    if kind == "iso":
        text, extra = _iso(rng)
    elif kind == "fanuc":
        text, extra = _fanuc(rng)
    elif kind == "heidenhain":
        text, extra = _heidenhain(rng, subs)
    else:
        text, extra = _sinumerik(rng, subs)
    suffix = {"iso": ".ngc", "fanuc": ".nc", "heidenhain": ".h", "sinumerik": ".mpf"}[kind]
    program = folder / f"gen{n}{suffix}"
    program.write_text(text)
    dialect = ["--dialect", kind] if kind == "fanuc" else []
    if kind == "fanuc" and rng.random() < 0.5:
        zero = rng.choice(["1,2,3", "1,2,3", "1,2,3", "nan,0,0"])
        extra = [*extra, "--work-offset", f"G54.1P{rng.randint(0, 50)}={zero}"]
    if kind in ("iso", "fanuc") and rng.random() < 0.3:
        extra = [*extra, *_control_files(rng, folder, n)]
    mode = rng.choice(["compensate", "compensate", "motion", "plain"])
    out = ["-o", str(folder / f"out{n}{suffix}")]
    if mode == "compensate":
        return ["compensate", "--machine", MACHINE, *dialect, *extra, str(program), *out]
    if mode == "motion":
        options = [e for e in extra if e not in ("--expand", "--expand-cycles")]  # (compensate's only)
        return ["motion", *dialect, *options, str(program)]
    return [*dialect, str(program), *out]
