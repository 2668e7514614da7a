"""Fanuc and Haas: where their reading of G code differs from LinuxCNC's.

The ISO interpreter (`interpreter.py`) already reads what Fanuc and LinuxCNC share, Fanuc's
corner rounding and M98/M99 subprograms among it.  These flavours add the settings that
Fanuc and Haas posts write on lines of their own and that move no axis, where LinuxCNC
reads the same codes otherwise (G5.1 is a spline there, G8 lathe radius mode):

* Fanuc (0i-MF / 30i operator's manuals): `G05.1 Q1` / `Q0`, AI contour control on and off;
  `G08 P1` / `P0`, advanced preview control on and off.
* Haas (Mill Operator's Manual, "G-codes"): also `G187 P1-P3 [E..]`, the smoothness level and
  corner tolerance; `G103 P..`, the limit of blocks looked ahead.  `M97 P<n> L<runs>` runs the
  program's own blocks from Nn to M99, a local subprogram (`Flow._m97`, `local_calls`); an M97 with
  other words in its block ends interpretation with a warning.  So do `G12`/`G13`,
  circular pocket milling clockwise / counterclockwise: the control spirals out from the point it
  stands on over I, K, Q with the D offset's cutter compensation (Haas VF-series manual 96-8000,
  "Circular Pocket Milling"), a path ncpp does not compute.
* Fanuc: `G45`-`G48`, tool position offset: the axes the block names move their programmed
  distance lengthened (G45), shortened (G46), lengthened twice (G47) or shortened twice (G48) by the
  offset value its D (or H) selects (Mitsubishi M700V/M70V programming manual, M system, "Tool Position
  Offset; G45 to G48"; NCT 2000M manual, "The Tool Compensation"; Mazak's and GSK's Fanuc-style EIA
  controls read them too): a move by an offset value ncpp is not told.  It ends interpretation with a
  warning from that block, where LinuxCNC refuses the code ("Unknown g code used").  (Haas's G47 is
  text engraving, "G47 Text Engraving (Group 00)": the strokes of the letters of its P0 comment, or of
  a serial number, from the control's font, a path ncpp does not compute; it ends interpretation
  with a warning too.  G45-G46 and G48 are none of Haas's codes: not read so there.)

Both have additional work offsets: Fanuc's `G54.1 P1`-`P48` ("Additional workpiece coordinate
systems", whose format is `G54.1 Pn` or `G54 Pn`: a G54 block with a P word selects the
additional system; the GSK 980MDc manual, which follows Fanuc, writes the same), Haas's `G154
P1`-`P99` ("G154 Select Work Coordinates P1-P99") and its older names G110-G129 for P1-P20
(Haas's "G10 Set Offsets": "P1-P20 G110-G129 references auxiliary coordinates").  One whose zero ncpp
is told (`--work-offset G54.1P3=X,Y,Z`, `G154P3=`, or a parameter file's #7001... / #14001...:
`offsets.py`) is followed as G54-G59 are (`_additional_offset`); one not told ends interpretation
with a warning, as does a block that selects one with other words in it (what else the block
does would run in the control's order around the new zero: not guessed at).  `G10 L20 Pn X.. Y..
Z..` sets additional work offset n's zero in machine coordinates on these controls (Fanuc 0i-MF
operator's manual, "Additional workpiece coordinate systems": "G10 L20 Pn IP_"; Haas's
"Programmable Offsets": `G10 L20 P2 G90 X100. Y80.` sets G111's), where LinuxCNC's sets system
P from the current point: followed as G10 L2 is (`_set_additional`), but out of scope where it
would leave a zero ncpp is not told partly unknown.  `G10 L2 P0` is out of scope: it sets the
external workpiece zero offset that shifts every system (Fanuc operator's manual, "Changing
workpiece coordinate system": P0 the external offset, P1-P6 G54-G59), where LinuxCNC's sets the
system in effect; a P that is an expression may be 0 there.
`G10 L2 Pn` in G91 adds its values to system n's zero, where in G90 it sets them (Fanuc Series
0i-MD operator's manual, "Changing workpiece coordinate system": with an incremental command the
value is added to the offset; Haas's "Programmable Offsets": `G10 L2 P1 G91 X60.` moves G54's X
60 mm); LinuxCNC's sets them in either.

Tool offsets a program sets, with `G10 L<n> P<offset> R<value>` (the value set in G90, added in G91):
L10 an H offset's geometry, L11 its wear, L12 a D offset's geometry, L13 its wear (the Fanuc-style
"G10: Programmable data input" of the PowerRoute Mill Programming Manual, 1.2.10; Mitsubishi M700V
programming manual, 12.7 "Programmed Compensation Input", tool compensation memory II; Haas's "G10
Set Offsets": "L10 Length offset amount (for H code)", "L1 or L11 Tool wear offset amount (for H
code)", "L12 Diameter offset amount (for D code)", "L13 Diameter wear offset amount (for D code)").
G43 Hn then applies geometry plus wear, as tool compensation memory C keeps them (Series 0i/0i Mate
Model B Connection Manual (Function), B-63833EN-1/02, 10 "Tool compensation memory C"); the length
--tool-table tells for offset n is its geometry, its wear 0.  With memory A the one value of an
offset is set by `G10 L11 P_ R_` (Series 16i/18i-PA operator's manual, B-63124EN/01, 15.3
"Tool compensation values, number of compensation values, and entering values from the program
(G10)": "the system allows L1 to be specified instead of L11"): so on Fanuc an L11 or L1 of an H
offset whose geometry the program has not set with L10 is out of scope (with memory A it would be
the whole length, with B and C the wear); on Haas it is the wear.  On Fanuc a D offset is a radius,
its geometry (L12) and wear (L13) kept apart by memory C, which L12 and L13 address: G41/G42 Dn
offsets the path by geometry plus wear (Series 15i/150i-MB descriptions, B-63782EN/01, 14.3 "Cutter
compensation": "an offset vector with a length equal to the radius of the tool"), the geometry the
told table's (half its diameter) until L12 sets it.  Haas's D offset set so is named a diameter,
which the control may read as a radius: G41/G42 with it offsets by a radius ncpp does not know (its
moves are corrected for their programmed points, with the warning a radius not told gets).  Any
other word in such a block is out of scope.

A G00 written in a G28 or G30 block (`G0 G28 G91 Z0.`, which Mastercam's and Fusion's Fanuc and Haas
posts write before each tool change) only sets the modal motion: these controls take G codes of
different groups in one block, and the group-00 return takes the axis words (Fanuc 0i-MF
operator's manual, "Preparatory function (G function)"; the page is not in ncpp's reference set,
the rule is read from the posts that write the block).  LinuxCNC refuses the block ("Cannot use two
g codes that both use axis values").

An H word needs no G43 in its block either: Fanuc takes it on its own (Fanuc Series 0i-MB operator's
manual, "G53, G28, and G30 commands in tool length offset mode": "independent specification of the H
command"), as the tool length offset number a later G43 uses or, in G43 mode, in place of the offset in
effect (Allen-Bradley 9/Series mill manual, "Modal G43, G44 and modal H-words": `H02` alone changes the
offset in G43 mode, `H0` gives it no value).  ncpp follows neither: such a block (`G53 G00 H0 Z-110`)
ends interpretation with a warning, where LinuxCNC refuses it ("H word with no G43 or G76 to use it").

A D word needs no G41/G42 in its block: the control keeps it and a later G41/G42 without D uses it
(`G43 H1 D1`, as Fanuc programs write with the tool length; Fanuc Series 15i-MA operator's manual,
"Cutter compensation C": the compensation values are assigned to the D codes, D0 always means 0,
and a value changed in offset mode takes effect from that block's end, which ncpp does not follow).
LinuxCNC refuses a D without G41/G42 ("D word with no G41 ...").

Fanuc's dwell takes its time in X as well as in P: `G04 X1.5` dwells 1.5 s (Fanuc Series 0i-MF / 16i
operator's manuals, "Dwell (G04)": "G04 X_ ; or G04 P_ ;", X with a decimal point in seconds, P in
milliseconds); the X is no axis word there.  LinuxCNC reads only P ("Cannot use axis values without a g
code that uses them").

A setting code written with other words in its block is out of scope too: a block that
both sets and moves is not one these controls' posts write.  So is G33.1, LinuxCNC's rigid tap:
these controls tap rigidly with M29 and G84.

A canned cycle drills along the axis normal to its plane, the taps G74 and G84 too: Y in G18, X
in G19 (Fanuc operator's manuals, "Canned cycle for drilling": "Positioning plane and drilling
axis", G17 Zp, G18 Yp, G19 Xp; the drilling axis is the basic axis not used to define the
positioning plane), as rs274ngc drills but does not tap there (`Interpreter.taps_in_any_plane`).

Coordinate system rotation `G68 X_ Y_ R_` / `G69` in G17, and in G18 (`G68 Z_ X_ R_`) and G19
(`G68 Y_ Z_ R_`), is followed (`_coordinate_rotation`, and `Interpreter._settle_rotation` for the
moves after it) where the Fanuc manual's rules leave nothing to a parameter (Fanuc Series
16/18/160/180-MC operator's manual, "Coordinate system rotation": the plane's two axis words the
centre, absolute; R the angle, counter-clockwise; without them the tool's position is the centre,
without R a parameter's angle; no G17-G19 in its mode; G91 moves after it run from where the tool
stood at G68; the first move after G69 absolute), Haas's alike (Mill Operator's Manual, "G68
Rotation": R from Setting 72 when not given, added in G91 with Setting 73).  Scaling (G51), G68.1 and the
tilted working plane (G68.2-G68.4) end interpretation by name.

Fanuc's programmable mirror image `G51.1 X_ Y_` / `G50.1 X_ Y_` is followed in G17 (`_mirror_image`; the
SINUMERIK 802D sl/840D ISO Milling programming manual 04.07, which documents Fanuc's dialect, 3.2
"Programmable mirror image"): the axis words of G51.1 give the "position and axis of symmetry" of each
axis it mirrors, those of G50.1 the axes it cancels; the blocks between "describe the contour" that is
mirrored, so each move goes where the control mirrors the program's point to and an increment (G91)
runs the other way; G51.1 and G50.1 move nothing (the machine stays where it is).  Mirrored in one axis
of the plane alone, "G02 and G03 are interchanged", and "G41 and G42 are interchanged" (the tool centre
the control offsets the mirrored contour to: `Interpreter._on_the_left`), and the direction of a
rotation.  What the manual forbids in its mode is out of scope: reference position returns (G27, G28,
G30) and the coordinate system codes (G52-G59, G92; G53 and G10 with them), and "G50.1 or G51.1 during
scaling or coordinate rotation mode"; so are G68 in its mode, another plane, Z or another axis
mirrored, a G51.1 in G91 or while a mirror image is in effect, G51.1 or G50.1 under cutter compensation,
and canned cycles (ncpp does not follow them under it).  A G50.1 whose axis words ncpp is not
mirroring cancels nothing: its words are no move.  Haas's mirror image is G100/G101 (Haas Mill Operator's Manual, G code list): G51.1
ends interpretation by name there.

A canned cycle's K is its repeats, as rs274ngc's L (the Fanuc Series 0i and 16i formats, `G81 X_ Y_ Z_ R_
F_ K_`, "K_: Number of repeats", as the Fanuc lathe operator's manual's drilling cycles give it; the
Series 15i-MA operator's manual counts them in L: "When L is used to specify the number of repeats"):
both are read, and a block with both is out of scope.  A block of K0 or L0 and no hole position stores
the cycle's data and drills nothing (cncci.com, "Two applications for L0"; `Interpreter._stored_cycle`);
one with a hole position is out of scope.  Haas counts repeats in L only ("G81 Drill Canned Cycle": "L
Number of holes if G91 is used"), and its L0 keeps rs274ngc's refusal.

A P in the block of a cycle whose format has none (G81 `X_ Y_ Z_ R_ F_ K_` as above, G73, G83 and G85 on
Fanuc) is kept as written and the cycle's moves are its own: the format's sequence has no dwell at the
bottom, and the manuals ncpp follows do not say what the control makes of such a P (keeps it for a later
block of the cycle, passes over it, or alarms), none of which moves an axis otherwise; the written
block carries it as the program did.  LinuxCNC refuses it ("P word with no G2 G3 G4 ... to use it").
--expand-cycles refuses such a block: whether the control dwells on that P is not known.

G76 is fine boring on both (Fanuc Series 15i-MA operator's manual, "Fine boring cycle (G76)": to X Y, to
R, feed to Z, dwell P, the spindle oriented and the tool shifted off the wall by Q or I J, out at rapid,
shifted back; Haas Mill Operator's Manual, "G76 Fine Boring Canned Cycle"), where LinuxCNC's G76 is a
lathe's threading: compensated hole by hole as the other cycles (`Interpreter.canned`), its X Y Z R
corrected, Q, I J and P as written; its moves are taken as straight out of the hole (the shift, whose
direction is a parameter of the control's, is the control's own and undone above the hole).
--expand-cycles refuses it (G0/G1 blocks cannot orient the spindle).

G87 is Fanuc's back boring (Series 15i-MA operator's manual, "Back boring cycle (G87)"): to X Y,
shifted by I J with the spindle oriented, down to R below the part, back over the hole, feed up to Z
(the top of the cut), shifted again, up to the initial level (G99 is not used) and back over the
hole; in G91 R counts from the initial level and Z from R.  It is compensated hole by hole as the
other cycles (`Interpreter._fanuc_back_bore`, `cycles.fanuc_back_bore`): X Y and Z corrected where
the cut ends, R where it starts, on the hole's centre; I J, an increment from the hole, as written.
A G87 with its shift in Q or with neither I nor J (the shift's direction a parameter of the control's:
"Shift specification by Q_", No. 6240), in G18 or G19 (where I J K name the shift otherwise), in G99,
with R not below Z, or after another cycle of the series without both I and J ("I, J, and K are modal
in a canned cycle": the one left out may be that cycle's) ends interpretation with a warning, where
rs274ngc's reading refused it; so does a Haas program's G87 (no Haas manual page in ncpp's reference
set gives its motion).

Canned cycles are a modal group of their own, group 09 beside group 01's G00-G03 (Fanuc 0i-MD /
15i-MA operator's manuals, "List of G codes"; Haas Mill Operator's Manual, "G80 Canned Cycle Cancel
(Group 09)"), so G80 cancels the cycle and leaves the G00-G03 mode it interrupted in effect: `G00 Z.1`,
`G81 ...`, `G80`, `G91 A45.` is a rapid.  rs274ngc keeps cycles in the motion group, and G80 leaves no
motion mode there ("Cannot use axis values without a g code that uses them").

Axis words before the program names any of G00-G03 (`G43 H01 Z50` after the safety line `G21 G90 G17
G54 G40 G49 G80`, as Fanuc and Haas posts write the tool's first move) move in the group-01 mode the
control holds at power-on or reset: on Fanuc G00, or G01 where parameter No. 3402#0 (G01) is set
("Parameter 3402#0 (G01) sets the default Group 01 interpolation mode to G01 (linear) instead of G00
(rapid positioning) upon power-up or clear", cnc.wiki "Fanuc Parameter 3402 G-Code Clear and Reset";
with 3402#6 (CLR) a reset clears the modes to these too); on Haas G00, the power-on default of group 01
(Haas Mill Operator's Manual, default G codes; Setting 56, "M30 Restores Default G": the page is not in
ncpp's reference set).  Either mode ends the move at its programmed point: ncpp follows it as a rapid
straight to that point and leaves it as programmed (`HELD`, `Interpreter._held_move`), with one warning
at the first, up to the first G00-G03 (a canned cycle, group 09, names none: after its G80 the mode held
at the start is in effect again).  Nothing ncpp writes adds a G00/G01 before that point, which would set
the mode the blocks after it run in.  Such a move with a corner (,C ,R) or under cutter compensation is
out of scope; with --expand-cycles one after a cycle written as G0/G1 blocks is refused.  LinuxCNC
refuses them ("Cannot use axis values without a g code that uses them").

A G28 or G30 under cutter compensation is out of scope: the control drops the offset vector at the
intermediate point and restores it after the return (NCT 2000M manual, "The Tool Compensation", a
control that follows Fanuc's compensation C; Fanuc 15i-MA, "Cutter compensation C"), which ncpp does
not follow.  LinuxCNC refuses it ("Cannot use g28 or g30 with cutter radius comp").

So is a G41 or G42 while compensation is on: these controls take it in offset mode and build the
offset vector anew at that block (Fanuc 16i/18i-MB B-63684EN, "Cutter compensation C", its details
of the offset mode: a change of the offset direction, or the same direction specified again; Haas
Mill Operator's Manual, "G41 2D Cutter Compensation Left"), which ncpp does not follow.  LinuxCNC
refuses it ("Cannot turn cutter radius comp on when on").

Macro B's external output statements, `POPEN`, `DPRNT[..]`, `BPRNT[..]` and `PCLOS`, send a line of text and
values to a printer or a PC (NCT 2000M manual, "Custom Macro": `DPRNT[ a #b [ c d ] ... ]`, characters,
variables and their digits before and after the point; Allen-Bradley 8520 manual, "Paramacros": `BPRNT[s
#p[d]...]`, `POPEN`, `PCLOS`; Haas writes DPRNT for its cycle logs).  They move nothing: ncpp passes them
through as they are, the text in the brackets unread.  LinuxCNC refuses them ("Unknown word where unary
operation could be").

An R arc whose end point is its start point (`G03 X40 Y50 R20` from X40 Y50, or `G02 R20` with no axis
word) is an arc of 0 degrees: the cutter does not move (Fanuc Series 16/18/160/180-C operator's manual,
"Circular interpolation": "if the end point is located at the same position as the start point and when R
is used, an arc of 0° is programmed"); ncpp passes the block through as it is, where LinuxCNC refuses it
("Current point same as end point of arc").  Under cutter compensation, and on Haas, it is still refused.
The same page: "If I, J, K, and R addresses are specified simultaneously, the arc specified by address R takes
precedence and the other are ignored": ncpp reads the arc from R, and the writer gives the compensated arc its
own centre words in place of them all, where LinuxCNC refuses the block ("Mixed radius ijk format for arc");
on Haas it is still refused.

With --expand-cycles, G82's and G89's dwell (Haas: G73's and G83's too) is written as a G04 with
the cycle's P as the program gave it, where the control reads both alike (`_dwell_word`).  Fanuc: a G04's P takes no decimal
point and counts 0.001 s, as a drilling cycle's P (SINUMERIK ISO Milling manual, which documents
Fanuc's dialect, "Dwell (G04)": "P_: Specify a time (decimal point not permitted)"); with feed per
revolution (G95) a G04 counts spindle revolutions.  Haas (Mill Operator's Manual, "G04 Dwell"):
"G04 P10. is a dwell of 10 seconds; G04 P10 is 10 milliseconds", and a cycle's P is in seconds
("G82", whose example is `P0.3`; "G83": "in seconds").  A P these rules leave open (a decimal point
on Fanuc, none on Haas, a variable, G95) is refused: the dwell would be a guess.
"""

from __future__ import annotations

from typing import cast

from ncpp.motion.cycles import CANNED
from ncpp.motion.expressions import vacant
from ncpp.motion.interpreter import IGNORED_STATEMENTS, MM_PER_INCH, Interpreter, _OutOfScope, interpreting
from ncpp.motion.offsets import ADDITIONAL, ADDITIONAL_CODES
from ncpp.motion.segments import Event, Pass, plane_letters
from ncpp.program.blocks import Block, Comment, ExprWord, Statement, Word

# Fanuc's common variables: #100-#199 cleared at power off, #500-#999 kept through it, both shared by
# every program the control runs (Fanuc Series 16i/18i-MB operator's manual B-63684EN, "Custom macro",
# "Variables", "Types of variables"), so one a program reads before it sets it holds what an earlier
# program, a probe cycle or the operator left there
COMMON_VARIABLES = frozenset(range(100, 200)) | frozenset(range(500, 1000))

# G code -> the words it takes, for the settings each flavour reads past
FANUC_SETTINGS: dict[float, frozenset[str]] = {5.1: frozenset("Q"), 8.0: frozenset("P")}
HAAS_SETTINGS = {**FANUC_SETTINGS, 187.0: frozenset("PE"), 103.0: frozenset("P")}
# The returns whose block may carry a G00 as well (module docstring)
RETURNS = frozenset((28.0, 30.0))
# Codes of the flavour that need what ncpp is not told (a sequence number's block; Haas does not
# write Fanuc's G54.1)
_POSITION_OFFSET = "tool position offset: the control lengthens or shortens the move by an offset value"
FANUC_UNFOLLOWED = {("G", 45.0): f"G45 ({_POSITION_OFFSET})", ("G", 46.0): f"G46 ({_POSITION_OFFSET})",
                    ("G", 47.0): f"G47 ({_POSITION_OFFSET} twice)",
                    ("G", 48.0): f"G48 ({_POSITION_OFFSET} twice)",
                    ("M", 97.0): "M97 (Haas's local subprogram call, which a Fanuc control has not: for a "
                                 "Haas program give --dialect haas)"}  # fmt: skip
HAAS_UNFOLLOWED = {("G", 54.1): "G54.1 (Fanuc's additional work offset; Haas selects its own with G154)",
                   ("M", 97.0): "M97 with other words in its block than P and L (a local subprogram call)",
                   ("G", 12.0): "G12 (Haas circular pocket milling, a path the control computes)",
                   ("G", 13.0): "G13 (Haas circular pocket milling, a path the control computes)",
                   ("G", 47.0): "G47 (Haas text engraving, a path the control computes from its font)"}  # fmt: skip


# What is out of scope under G68: codes that change the plane it turns in (Fanuc: "G17, G18 or G19 must not be
# designated in the mode of coordinate system rotation") or the frame its centre is in, and offsets set in it
NOT_UNDER_G68 = frozenset((17.0, 18.0, 19.0, 10.0, 52.0, 92.0, 92.1, 92.2, 92.3, 54.0, 55.0, 56.0, 57.0, 58.0,
                           59.0, 54.1, 154.0, *(float(n) for n in range(110, 130))))  # fmt: skip

# The G codes a G69 block may carry besides N: modes of other groups that move nothing and leave the
# frame G68 turned alone (Fanuc Series 30i-MB G code list: G69 in group 16; G90/G91 03, G94/G95 05, G98/G99
# 10, G80 09, G40 07, G49 08, G15 17, G50 11, G50.1 22), set once the rotation is cancelled
G69_COMPANIONS = frozenset((90.0, 91.0, 94.0, 95.0, 98.0, 99.0, 80.0, 40.0, 49.0, 15.0, 50.0, 50.1))

# Frames these controls turn, scale or tilt that ncpp does not follow, named before the block's words are
# checked (a G51's P is its scale, no dwell): scaling, the programmable mirror image, G68.1's rotation (a
# lathe's), and the tilted working plane G68.2-G68.4 (Fanuc 30i-MB operator's manual)
UNFOLLOWED_FRAMES = {51.0: "scaling", 51.1: "mirroring", 68.1: "coordinate rotation",
                     **{code: "tilted working plane" for code in (68.2, 68.3, 68.4)}}  # fmt: skip


# What is out of scope under G51.1 (SINUMERIK 802D sl/840D ISO Milling programming manual, 3.2 "Programmable
# mirror image", Limitations: "Do not use G codes related to reference position return (G27,G28,G30), or
# commands related to the coordinate system (G52 to G59,G92, etc.) in programmable mirror image mode"), and
# what ncpp does not follow there: another plane, G53 and G10, G68
NOT_UNDER_G51_1 = frozenset((18.0, 19.0, 10.0, 27.0, 28.0, 29.0, 30.0, 52.0, 53.0, 54.0, 55.0, 56.0, 57.0,
                             58.0, 59.0, 54.1, 68.0, 92.0, 92.1))  # fmt: skip
# The words of a G51.1 or G50.1 block ncpp follows: N, G90 or G91, and the axes it names
MIRROR_LETTERS = frozenset("NGXYZ")


# The G codes whose block takes an H: the tool length offsets, the tool position offsets (whose number
# Mazak's and Mitsubishi's G45-G48 take in H or D) and the macro calls' arguments
_H_CODES = frozenset((43.0, 43.2, 43.4, 43.5, 44.0, 45.0, 46.0, 47.0, 48.0, 65.0, 66.0))


# Signatures of plain blocks (per interpreter class) and whether their G codes are all ones
# `FanucInterpreter.block` hands on unchecked (`_plain_g`)
_PLAIN_SIGNATURES: dict[tuple[type, str], bool] = {}


class FanucInterpreter(Interpreter):
    settings: dict[float, frozenset[str]] = FANUC_SETTINGS
    kept_variables = COMMON_VARIABLES
    unfollowed: dict[tuple[str, float], str] = FANUC_UNFOLLOWED
    additional = "G54.1"  # the code that selects an additional work offset, with P
    g54_with_p = True  # `G54 Pn` selects additional work offset n as `G54.1 Pn` does
    numbered = range(0)  # G codes that each select one additional work offset (Haas's G110-G129)
    rigid_tapping = False  # (Fanuc taps rigidly with M29 and G84: G33.1 is LinuxCNC's)
    modal_d = True  # `G43 H1 D1`: D alone selects the radius offset (module docstring)
    dwell_x = True  # `G04 X1.5`: a dwell of 1.5 s (module docstring)
    any_cycle_p = True  # `G81 ... P500`: the P kept as written, no dwell of G81's (module docstring)
    taps_in_any_plane = True  # G74/G84 in G18/G19 tap along the normal (module docstring)
    cycles_own_group = True  # G80 leaves the G0-G3 mode before the cycle in effect (module docstring)
    holds_start_mode = True  # `G43 H01 Z50` before any G00-G03: the start mode's (module docstring)
    back_bore_holes = False  # G87 reads R Z Q K otherwise than rs274ngc (`Interpreter.back_bore_holes`)
    repeat_letters: tuple[str, ...] = (
        "L",
        "K",
    )  # a cycle's repeats: K, or L on the Series 15 (module docstring)
    stores_cycle = True  # `G81 R.. Z.. L0`: the cycle's data kept, no hole (`Interpreter._stored_cycle`)
    fanuc_back_bore = True  # G87 read as Fanuc's back bore, compensated hole by hole (module docstring)
    canned = CANNED | {76.0}  # G76: fine boring, compensated hole by hole (module docstring)
    returns_under_comp = True  # G28/G30 under G41/G42: out of scope (module docstring)
    comp_again = True  # G41/G42 under G41/G42: out of scope (module docstring)
    external_output = True  # POPEN, DPRNT[..], BPRNT[..], PCLOS pass through (module docstring)
    repeats_in_p = True  # `M98 P51002`: O1002 five times (`Flow._m98`)
    main_after_subprograms = True  # subprograms before the main program in a file (`Flow._stored_first`)
    still_r_arc = True  # `G02 R..` ending where it starts does not move (module docstring)
    r_over_ijk = True  # `G02 X.. Y.. R.. I.. J..`: R's arc, I J ignored (module docstring)
    independent_h = True  # `G53 G00 H0 Z-110`: an H without G43, out of scope (module docstring)
    incremental_zero_set = True  # `G91 G10 L2 P1 X10.` adds 10 to G54's X (module docstring)
    rotating_g10 = False  # (an R in G10 L2 is no rotation there)
    mirror_image = True  # G51.1 / G50.1: the programmable mirror image (module docstring)
    g92_speed_clamp = True  # `G92 S4000`: refused as the spindle speed clamp it is (`G92_SPEED_CLAMP`)
    fanuc_variables = True  # `#5003`, `#3020`: the control's system variables, in every program
    logic = "binary"  # `[20 OR 20]`: out of scope, `[#1 GT 0] AND [#2 GT 0]` followed (`Parameters.logic`)
    # Polar coordinates, scaling, programmable mirror image and coordinate rotation cancel (Fanuc Series
    # 0i-MD operator's manual, G code list: G15, G50, G50.1, G69)
    idle_cancels = frozenset((15.0, 50.0, 50.1, 69.0))
    g10_l_numbers = frozenset((1.0, 2.0, 10.0, 11.0, 12.0, 13.0, 20.0))  # (L10-L13: tool offset memory)
    # A G10 L11 (or L1) of an H offset whose geometry the program has not set: its meaning depends on
    # the control's tool compensation memory (module docstring); Haas's is the wear
    wear_alone = False
    # A D offset G10 L12/L13 sets is a radius (module docstring); Haas's may be a diameter
    d_radii = True

    def _cancels_nothing(self, code: float, block: Block) -> bool:
        if code == 69.0:
            return self.g68 is None
        if code == 50.0:  # (`G50 S..`: a lathe's spindle speed clamp, which `_check_scope` names)
            return not any(type(item) is Word and item.letter == "S" for item in block.items)
        return True

    def block(self, block: Block) -> Event | tuple[Event, ...]:
        if self.mirror:
            self._check_mirrored(block)
        signature = block.signature
        if self.independent_h and (signature is None or "H" in signature):
            h = _independent_h(block)
            if h is not None:
                raise _OutOfScope("an H word without G43 (Fanuc's tool length offset number on its own)",
                                  h.start + 1)  # fmt: skip
        if signature is not None and "M" not in signature and self._plain_g(signature, block):
            return super().block(block)  # no G code checked below (the most): no setting, nothing unfollowed
        words = [item for item in block.items if type(item) is Word]
        if self.dwell_x and _dwell_in_x(block, words):
            return Pass(block)
        for word in words:
            if word.letter == "G" and (word.value == 68.0 or word.value == 69.0 and self.g68 is not None):
                return self._coordinate_rotation(block, word)
            if word.letter == "G" and self.mirror_image and word.value in (50.1, 51.1):
                mirrored = self._mirror_image(block, word)
                if mirrored is not None:
                    return mirrored
            if word.letter == "G" and word.value in UNFOLLOWED_FRAMES:
                raise _OutOfScope(f"{UNFOLLOWED_FRAMES[word.value]} G{word.number}", word.start + 1)
            if word.letter == "G" and word.value in NOT_UNDER_G68 and self.g68 is not None:
                raise _OutOfScope(f"G{word.number} under coordinate system rotation G68", word.start + 1)
        for word in words:
            if word.letter == "G" and (
                word.value == ADDITIONAL_CODES[self.additional][0]
                or (word.value == 54.0 and self.g54_with_p and any(w.letter == "P" for w in words))
            ):
                return self._additional_offset(block, word)
            if word.letter == "G" and word.value.is_integer() and int(word.value) in self.numbered:
                return self._additional_offset(block, word, int(word.value) - self.numbered.start + 1)
            if (
                word.letter == "G"
                and word.value == 10.0
                and any(w.letter == "L" and w.value == 20 for w in words)
            ):
                return self._set_additional(block, word)
            if word.letter == "G" and word.value == 10.0 and _external_offset(block, words):
                raise _OutOfScope("G10 L2 P0 (it sets the external work offset, which shifts every system)",
                                  word.start + 1)  # fmt: skip
            reason = self.unfollowed.get((word.letter, word.value))
            if reason is not None:
                raise _OutOfScope(reason, word.start + 1)
        setting = next((w for w in words if w.letter == "G" and w.value in self.settings), None)
        if setting is None:
            return super().block(block)
        allowed = self.settings[setting.value] | {"N"}
        if any(type(item) is not Comment and item is not setting and not (type(item) is Word and item.letter in allowed)
               for item in block.items):  # fmt: skip
            raise _OutOfScope(f"G{setting.number} with other words in its block", setting.start + 1)
        return Pass(block)

    def _plain_g(self, signature: str, block: Block) -> bool:
        """Whether a plain block of this signature has no G code that `block` checks (its G words'
        numbers are in the signature: one answer for all its blocks)."""
        key = (type(self), signature)
        plain = _PLAIN_SIGNATURES.get(key)
        if plain is None:
            checked = self._checked_g()
            plain = not any(type(w) is Word and w.letter == "G" and w.value in checked for w in block.items)
            if len(_PLAIN_SIGNATURES) >= 4096:  # (a program has few; memory stays flat)
                _PLAIN_SIGNATURES.clear()
            _PLAIN_SIGNATURES[key] = plain
        return plain

    @classmethod
    def _checked_g(cls) -> frozenset[float]:
        """The G codes `block` looks at before it hands a block on: dwells, frames, offsets, settings
        and those it does not follow."""
        additional = ADDITIONAL_CODES[cls.additional][0]
        return frozenset((4.0, 10.0, 54.0, 68.0, 69.0, 50.1, additional, *UNFOLLOWED_FRAMES, *NOT_UNDER_G68,
                          *(float(n) for n in cls.numbered), *cls.settings,
                          *(value for letter, value in cls.unfollowed if letter == "G")))  # fmt: skip

    # the P of a cycle that a G04 P reads alike: whether it has a decimal point (module docstring)
    dwell_point = False

    def _dwell_word(self, block: Block, item) -> str:
        """The cycle's P as the program gave it, where a G04 P reads it alike (module docstring)."""
        word = self.cycle_p_word
        told = f"P{word.number}" if type(word) is Word else "from a variable"
        point = "in seconds with" if self.dwell_point else "as a whole number, without"
        if self.per_revolution:
            why = "with feed per revolution (G95) a G04 may count spindle revolutions"
        elif type(word) is not Word or ("." in word.number) != self.dwell_point:
            why = f"this control's G04 reads only a P {point} a decimal point as the cycle's"
        else:
            return told
        self._fail(f"--expand-cycles: the canned cycle's dwell {told} cannot be written as a G04 ({why}); "
                   "leave the option out, the cycle is then compensated", block, item)  # fmt: skip

    def _motion_of_words(self, block, mode0, mode1, mode1_item, axis_item, polar_item) -> float | None:
        """`G0 G28 ...`: the return takes the axis words, the G0 is only the modal motion after it."""
        if mode0 in RETURNS and mode1 == 0.0:
            mode1 = mode1_item = None
        return super()._motion_of_words(block, mode0, mode1, mode1_item, axis_item, polar_item)

    def _coordinate_rotation(self, block: Block, code: Word) -> Event | tuple[Event, ...]:
        """`G68 X_ Y_ R_` in G17, `G68 Z_ X_ R_` in G18, `G68 Y_ Z_ R_` in G19 (the plane's code may stand in
        its block): the program's coordinates in that plane turned about the centre its two axis words give
        (absolute) by R degrees counter-clockwise, from the next block on; `G69` cancels it (Fanuc Series
        16/18-MC operator's manual, "Coordinate system rotation"; Fanuc Series 0i connection manual
        (function) B-64113EN-1, 11.12 "Coordinate system rotation": "G17 (G18 or G19): Select the plane
        that contains the figure to be rotated", α β "Absolute command for two of the X_, Y_, and Z_ axes
        that correspond to the current plane selected", R "A positive angular displacement indicates counter
        clockwise rotation"; Haas Mill Operator's Manual 96-8000, "G68 Rotation": "a optional center of
        rotation for the first axis of the selected plane", "For a positive angle, the rotation is
        counterclockwise").
        Counter-clockwise in G18 and G19 is the plane's own sense, that of its arcs' G03: seen from the
        positive end of the axis normal to it, from the plane's first axis toward its second, Z toward X in
        G18 and Y toward Z in G19 (`PLANE_AXES`; Haas Mill Operator's Manual, "G17 XY / G18 XZ / G19 YZ
        Plane Selection": G18's circular motion as the operator sees it "looking from the rear of the
        machine toward the front control panel", G19's "looking across the table from the side of the
        machine where the control panel is mounted").
        The machine stays where it is; the moves after it follow `_settle_rotation`'s rules.
        Cutter compensation turned on after it and off before G69 offsets the turned contour (the order
        the Haas training manual "Advanced Haas Mill Programming Techniques", G68, gives: "the G41 or G42
        commands should be turned on after the G68 rotation is called up and turned off with G40 before
        the G68 is cancelled with a G69"; `Interpreter._cutter_compensation`).
        Out of scope: other words in the block (the third axis: a three-dimensional conversion's), a G68
        under G68 or under cutter compensation (from G41/G42 to the move after G40), a G68 without R or in
        G91, whose angle a parameter gives or adds to (Fanuc No. 5410 and, 15i, No. 6400 bit 0; Haas
        Settings 72 and 73), and one without both of its plane's axis words: the control then turns about
        where the tool stands, which compensation moves (the program's turned points with it).  A plane
        code under G68 is out of scope too (`NOT_UNDER_G68`; Fanuc Series 15i-MA operator's manual: "G17,
        G18 or G19 must not be designated in the mode of coordinate system rotation"), and so is an arc or
        cutter compensation in another plane than the rotation's (Fanuc Series 0i-A connection manual
        (function) B-63503EN-1, "Coordinate system rotation", alarm 144 "ILLEGAL PLANE SELECTED": "The
        coordinate rotation plane and arc or cutter compensation C plane must be the same").  The words may be expressions (`R#21`, `Y[#27/2]`): the manual's words take a
        macro's values as any word does; but not under --expand, which writes the G68 block's text where its
        variables are no longer set."""
        col, name = code.start + 1, f"G{code.number}"
        others = [item for item in block.items if type(item) is not Comment and item is not code
                  and not (type(item) is Statement and item.kind in IGNORED_STATEMENTS)]  # fmt: skip
        words = [word for item in others if (word := self._rotation_word(item, block, name, col)) is not None]
        if code.value == 69.0:
            return self._cancel_rotation(block, words, col)
        planes = [int(w.value) for w in words if w.letter == "G" and w.value in (17.0, 18.0, 19.0)]
        plane = planes[0] if planes else self.plane
        letters = plane_letters(plane)
        first, second = letters[0], letters[1]
        if len(planes) > 1 or any(
            w.letter not in ("N", "R", "G", first, second) or (w.letter == "G" and w.value != plane)
            for w in words
        ):
            raise _OutOfScope(
                f"G68 with other words in its block than G{plane}, {first}, {second} and R", col
            )
        given = {w.letter: w.value for w in words}
        why = (
            "while a rotation is in effect" if self.g68 is not None
            else "under cutter compensation" if self._compensating()
            else "without R (its angle is then a parameter's)" if "R" not in given
            else "in G91 (a parameter makes its R absolute or added)" if not self.absolute
            else f"without {first} and {second} (its centre is then where the tool stands, which compensation moves)"
            if not {first, second} <= given.keys()
            else None
        )  # fmt: skip
        if why is not None:
            raise _OutOfScope(f"G68 {why}", col)
        if planes:
            self._set(plane=plane)
        self._keeping_machine(lambda: self._turn(plane, (given["R"], given[first], given[second])))
        self.unsettled_rotation, self.rotation_homed = 68.0, set()
        return Pass(block)

    def _check_mirrored(self, block: Block) -> None:
        """Under G51.1: a G code of the block that the manual forbids in its mode, or ncpp does not follow
        there (`NOT_UNDER_G51_1`), is out of scope."""
        for item in block.items:
            if type(item) is Word and item.letter == "G" and item.value in NOT_UNDER_G51_1:
                raise _OutOfScope(f"G{item.number} under a mirror image G51.1", item.start + 1)

    def _mirror_image(self, block: Block, code: Word) -> Pass | None:
        """`G51.1 X_ Y_` (G17): X and Y, those it names, mirrored about the coordinates it gives them;
        `G50.1 X_ Y_`: the mirror image of the axes it names cancelled (module docstring).  The machine stays
        where it is; the moves after it are mirrored (`Context.mirror`).  A block with other words than N
        and the axis words is out of scope, but for a G50.1 without axis words where nothing is mirrored,
        which cancels nothing as before (None: the block is read as any other)."""
        name, col = f"G{code.number}", code.start + 1
        others = [item for item in block.items if type(item) is not Comment and item is not code]
        axes = [item for item in others if isinstance(item, (Word, ExprWord)) and item.letter in "XYZ"]
        if code.value == 50.1 and not (axes or self.mirror):
            return None
        words = [w for item in others if (w := self._rotation_word(item, block, name, col)) is not None]
        other = next((w for w in words if w.letter not in MIRROR_LETTERS or w.letter == "G" and w.value not in
                      (90.0, 91.0)), None)  # fmt: skip
        if other is not None:
            raise _OutOfScope(f"{name} with {other.letter}{other.number} in its block", col)
        modes = [w.value == 90.0 for w in words if w.letter == "G"]
        if modes:
            self._set(absolute=modes[-1])
        named = {"XYZ".index(w.letter): w.value for w in words if w.letter in "XYZ"}
        if code.value == 50.1:
            return self._cancel_mirror(block, name, col, named)
        why = (
            "while a mirror image is in effect" if self.mirror
            else "under a coordinate system rotation G68" if self.g68 is not None
            else f"in G{self.plane} (followed in G17)" if self.plane != 17
            else "in G91 (its axis words are the axis of symmetry's position)" if not self.absolute
            else "under cutter compensation" if self._compensating()
            else f"in a canned cycle's mode (G{self.motion:g})" if self.motion in self.canned
            else "of Z (followed for X and Y)" if 2 in named
            else "without X or Y" if not named
            else None
        )  # fmt: skip
        if why is not None:
            raise _OutOfScope(f"{name} {why}", col)
        mirror = tuple(sorted(named.items()))
        self._keeping_machine(lambda: setattr(self, "mirror", mirror))
        return Pass(block)

    def _cancel_mirror(self, block: Block, name: str, col: int, named: dict[int, float]) -> Pass:
        """G50.1: the mirror image of the axes it names cancelled, its axis words no move."""
        if self.mirror and not named:
            raise _OutOfScope(f"{name} without axis words (which axes it cancels is not said)", col)
        kept = tuple((axis, centre) for axis, centre in self.mirror if axis not in named)
        if kept != self.mirror:
            if self._compensating():
                raise _OutOfScope(f"{name} under cutter compensation", col)
            self._keeping_machine(lambda: setattr(self, "mirror", kept))
        return Pass(block)

    def _turn(self, plane: int, rotation: tuple[float, float, float]) -> None:
        """G68 in effect: `rotation` (degrees, the centre's coordinates) in `plane`."""
        self.g68, self.g68_plane = rotation, plane

    def _cancel_rotation(self, block: Block, words: list[Word], col: int) -> Event | tuple[Event, ...]:
        """`G69`, with N and the modes of other groups that move nothing (`G69_COMPANIONS`: `G69 G94`,
        `G90 G80 G69`) in its block: the rotation cancelled, the machine where it is, then the block's
        modes set as in any block (G69 then cancels nothing).  A G69 with a plane (which the manual
        forbids under G68), a work offset, a move or any other word is out of scope; so is one under
        cutter compensation (from G41/G42 to the move after G40: `_coordinate_rotation`)."""
        other = next((w for w in words if w.letter != "N" and not (w.letter == "G" and w.value in G69_COMPANIONS)),
                     None)  # fmt: skip
        if other is not None:
            raise _OutOfScope(f"G69 with {other.letter}{other.number} in its block", col)
        if self._compensating():
            raise _OutOfScope("G69 under cutter compensation", col)
        if self.g68 is not None:
            self._keeping_machine(lambda: setattr(self, "g68", None))
            self.unsettled_rotation, self.rotation_homed = 69.0, set()
        if all(w.letter == "N" for w in words):
            return Pass(block)
        return super().block(block)

    def _rotation_word(self, item, block: Block, name: str, col: int) -> Word | None:
        """A word of a G68 or G69 block, an X Y or R expression with the value it has now (None for
        one of a vacant variable, which is no word)."""
        if type(item) is Word:
            return item
        if (
            type(item) is ExprWord and item.letter in "XYR" and self.expansion is None
        ):  # (written out: its text)
            if vacant(item.expr, self.params):
                return None
            return Word(item.letter, self._evaluate(item.expr, block, item), "", item.start, item.end)
        raise _OutOfScope(f"{name} with a value from a variable", col)

    def _additional_offset(self, block: Block, code: Word, fixed: int | None = None) -> Pass:
        """`G54.1 Pn` (Haas: `G154 Pn`; or a code that names one, `fixed`: n) with nothing else
        but N and comments: additional work offset n, in effect from here as a G54-G59 selected
        is, where its zero is told."""
        name, col = f"G{code.number}", code.start + 1
        others = [item for item in block.items if type(item) is not Comment and item is not code]
        ps = [item for item in others if type(item) is Word and item.letter == "P"]
        if fixed is None and len(ps) != 1:
            raise _OutOfScope(f"{name} without one P (an additional work offset ncpp cannot tell)", col)
        given = ps[0] if fixed is None else None
        if any(item is not given and not (type(item) is Word and item.letter == "N") for item in others):
            raise _OutOfScope(f"{name} with other words in its block", col)
        last = ADDITIONAL_CODES[self.additional][1]
        if given is not None:
            n = int(given.value) if given.value == int(given.value) and 1 <= given.value <= last else 0
        else:
            n = fixed or 0
        said = f"{name} P{given.number}" if given is not None else name
        number = ADDITIONAL + n
        if n == 0 or number not in self.g5x:
            told = f": give --work-offset {self.additional}P{n}=X,Y,Z or --var-file" if n else ""
            raise _OutOfScope(f"{said} (an additional work offset ncpp is not told{told})", col)
        if self.cutter_comp is not None:
            raise _OutOfScope(f"{name} under cutter compensation", col)
        self._coordinate_system(number)
        return Pass(block, zero_told=number if number in self.told_zeros else None)

    def _set_additional(self, block: Block, code: Word) -> Pass:
        """`G10 L20 Pn X.. Y.. Z..`: additional work offset n's zero in machine coordinates, added to
        it in G91 (module docstring), with nothing else but G90/G91, N and comments in the block.
        Out of scope where it would leave the zero partly unknown (some axes of an offset ncpp is
        not told) or takes a value from a variable."""
        col, last = code.start + 1, ADDITIONAL_CODES[self.additional][1]
        others = [item for item in block.items if type(item) is not Comment and item is not code]
        if any(type(item) is not Word for item in others):
            raise _OutOfScope("G10 L20 with a value from a variable (it sets an additional work offset)", col)
        words = cast(list[Word], others)
        ps = [w for w in words if w.letter == "P"]
        if len(ps) != 1 or not (ps[0].value.is_integer() and 1 <= ps[0].value <= last):
            raise _OutOfScope(f"G10 L20 without one P of 1-{last} (the additional work offset it sets)", col)
        modes = [w.value for w in words if w.letter == "G"]
        if any(m not in (90.0, 91.0) for m in modes) or any(w.letter not in "LPNXYZG" for w in words):
            raise _OutOfScope("G10 L20 with other words in its block", col)
        absolute = modes[-1] == 90.0 if modes else self.absolute
        number = ADDITIONAL + int(ps[0].value)
        given = {"XYZ".index(w.letter): w.value for w in words if w.letter in "XYZ"}
        if number not in self.g5x and (not absolute or len(given) < 3):
            told = f"give --work-offset {self.additional}P{int(ps[0].value)}=X,Y,Z"
            raise _OutOfScope(f"G10 L20 P{ps[0].number} of some axes of an additional work offset ncpp is "
                              f"not told ({told})", col)  # fmt: skip
        if number == self.coord_system and self.cutter_comp is not None:
            raise _OutOfScope("G10 L20 of the work offset in effect under cutter compensation", col)
        old = self.g5x.get(number, [0.0] * 9)
        new = old[:]
        for i, value in given.items():
            new[i] = value + (0.0 if absolute else old[i])
        self._zero_set(number, set(given), l20=False, added=not absolute)
        self.told_zeros.discard(number)
        self.g5x[number] = new
        if modes:
            self._set(absolute=absolute)
        if number == self.coord_system:
            self._shift(old, new)
        return Pass(block)

    def _set_tool_offsets(self, block: Block, words: dict, given: list[tuple[int, float]]) -> None:
        """`G10 L10-L13 P<n> R<value>`: H offset n's geometry (L10) or wear (L11, and L1), D offset n's
        geometry (L12) or wear (L13), set in G90 and added to in G91 (module docstring).  G43 Hn then
        applies geometry plus wear, G41/G42 Dn a D offset's (`_set_d_offset`)."""
        l_number, col = words["L"][0], words["L"][1].start + 1
        name = f"G10 L{l_number:g}"
        if given or words.keys() - {"L", "P", "R"}:
            raise _OutOfScope(f"{name} with other words than P and R (a tool offset's number and value)", col)
        if "P" not in words or "R" not in words:
            raise _OutOfScope(f"{name} without P or R (a tool offset's number and value)", col)
        p, p_item = words["P"]
        if p != int(p) or p < 1:
            raise _OutOfScope(f"{name} with P{p:g}, no tool offset number", p_item.start + 1)
        number, value = int(p), words["R"][0] * (MM_PER_INCH if self.inch else 1.0)
        if l_number in (12.0, 13.0):
            self._set_d_offset(number, value, l_number == 13.0)
            return
        wear = l_number in (1.0, 11.0)
        if wear and not self.wear_alone and number not in self.h_memory:
            raise _OutOfScope(f"{name} of H offset {number}, whose geometry the program has not set with "
                              "G10 L10 (with tool compensation memory A it sets the whole offset, with B "
                              "and C its wear)", col)  # fmt: skip
        told = self.tools.offset(number) if self.tools is not None else None
        geometry, worn = self.h_memory.get(number, (None if told is None else told[2], 0.0))
        if wear:
            worn = value + (0.0 if self.absolute else worn)
        elif self.absolute or geometry is not None:
            geometry = value + (0.0 if self.absolute else geometry or 0.0)
        self.h_memory[number] = (geometry, worn)
        if geometry is not None:
            self.set_offsets[number] = {2: geometry + worn}

    def _set_d_offset(self, number: int, value: float, wear: bool) -> None:
        """`G10 L12` / `L13 P<n> R<value>`: D offset n's geometry / wear in tool compensation memory C,
        radii (module docstring), set in G90 and added to in G91; G41/G42 Dn offset by geometry plus
        wear.  Its geometry is the told table's (half the diameter) until the program sets it (none
        told: not known, and no more after a wear).  A negative sum, which swaps G41 and G42 on a Fanuc,
        and a D offset of a control that may keep diameters (`d_radii`) are radii ncpp does not know."""
        if not self.d_radii:
            self.set_radii[number] = None
            return
        told = None if self.tools is None else self.tools.diameter(number) / 2
        geometry, worn = self.d_memory.get(number, (told, 0.0))
        if wear:
            worn = value + (0.0 if self.absolute else worn)
        elif self.absolute or geometry is not None:
            geometry = value + (0.0 if self.absolute else geometry or 0.0)
        self.d_memory[number] = (geometry, worn)
        radius = None if geometry is None else geometry + worn
        self.set_radii[number] = radius if radius is not None and radius >= 0.0 else None


class HaasInterpreter(FanucInterpreter):
    """Haas: also a P on G73 and G83, the pause at the bottom of each hole after its last peck, which
    holds for the cycle's next blocks until it is cancelled (Haas Mill Operator's Manual 96-8000, "G73
    High-Speed Peck Drilling Canned Cycle" and "G83 Normal Peck Drilling Canned Cycle": "P Optional
    pause at end of last peck, in seconds"): the holes' moves are those without it."""

    settings = HAAS_SETTINGS
    # (Haas Mill Operator's Manual, G code list: "G50 Cancel Scaling", "G69 Cancel G68 Rotation"; its mirror
    # image is G100/G101, and it lists no polar coordinates)
    idle_cancels = frozenset((50.0, 69.0))
    mirror_image = False
    peck_dwell = True
    dwell_point = True
    # ("G81 Drill Canned Cycle": "L Number of holes if G91 is used"; its G73 and G83 read I J K as pecks)
    repeat_letters = ("L",)
    stores_cycle = False  # (no Haas manual page in ncpp's reference set says what L0 does)
    fanuc_back_bore = False  # (no Haas manual page in ncpp's reference set gives G87 as Fanuc's back bore)
    unfollowed = HAAS_UNFOLLOWED
    additional = "G154"
    g54_with_p = False  # (Haas's manual gives G54 no P)
    numbered = range(110, 130)
    dwell_x = False  # (Haas's manual gives G04 a P only)
    # ("M98 Sub Program Call": "M98 Pnnnn (Pnnnn is the number of the program being called)", runs in L;
    # its programs are numbered to O99999)
    repeats_in_p = False
    # ("M97 Local Sub-Program Call": the blocks from Nn of the same program to its M99, L times; `Flow._m97`)
    local_calls = True
    still_r_arc = False  # (no Haas manual page in ncpp's reference set says a 0-degree R arc does not move)
    r_over_ijk = False  # (nor that R wins over I, J, K)
    independent_h = False  # (nor that an H goes without G43)
    wear_alone = True  # ("G10 Set Offsets": "L1 or L11 Tool wear offset amount (for H code)")
    d_radii = False  # ("L12 Diameter offset amount (for D code)": a diameter, or a radius as set up)
    # The NGC control's general-purpose variables, kept at power off, where its system variables
    # (#1000-#9999, #11000 on) are the control's (the Haas NGC manual's "System Variables" table, as
    # zappettiniconsulting.com/wiki/haas-system-variables quotes it: #10000-#10999 general-purpose,
    # r/w, #100-#999 their legacy numbers; #3020 the power-on timer, read only)
    kept_variables = COMMON_VARIABLES | frozenset(range(10000, 11000))
    logic = "bitwise"  # ("Logical Operators": on the bits of the integer parts, `expressions.BITWISE`)


interpret = interpreting(FanucInterpreter)
interpret_haas = interpreting(HaasInterpreter)


def _independent_h(block: Block) -> Word | ExprWord | None:
    """The block's H word where no G code of the block takes it (module docstring), else None."""
    words = [item for item in block.items if type(item) is Word or type(item) is ExprWord]
    h = next((w for w in words if w.letter == "H"), None)
    if h is None or any(type(w) is Word and w.letter == "G" and w.value in _H_CODES for w in words):
        return None
    return h


def _dwell_in_x(block: Block, words: list[Word]) -> bool:
    """`G04 X1.5`: a dwell whose time is X; out of scope with other words in its block (what else the
    block does is not a dwell's)."""
    g4 = next((w for w in words if w.letter == "G" and w.value == 4.0), None)
    times = [i for i in block.items if (type(i) is Word or type(i) is ExprWord) and i.letter in "XP"]
    if g4 is None or [i.letter for i in times] != ["X"]:
        return False
    kept = (g4, times[0])
    others = (i for i in block.items if type(i) is not Comment and i not in kept)
    if any(not (type(i) is Word and i.letter == "N") for i in others):
        raise _OutOfScope("G04 X (a dwell) with other words in its block", g4.start + 1)
    return True


def _external_offset(block: Block, words: list[Word]) -> bool:
    """A `G10 L2` block whose P is 0, or an expression that may be (Fanuc's external offset)."""
    if not any(w.letter == "L" and w.value == 2 for w in words):
        return False
    for item in block.items:
        if (type(item) is Word or type(item) is ExprWord) and item.letter == "P":
            return type(item) is ExprWord or item.value == 0
    return False
