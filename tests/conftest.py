"""Shared test fixtures: where the third-party corpus and the oracle live."""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("NCPP_SHARED", ROOT.parent / "shared"))
CORPUS = SHARED / "corpus"
RS274 = SHARED / "tools" / "rs274"
# A machine file for tests that need ncpp to read a program: without one it passes it through unread
READING = ROOT / "tests" / "machines" / "reading.toml"

# Files that are data or oracles beside programs, not programs.
NOT_PROGRAMS = ("expected", "README", ".tbl", "__expect__stdout", "__expect__stderr", ".csv", "MANIFEST.tsv")


# Test tiers.  `pytest` runs the fast tier: the tests below are deselected (pyproject's addopts)
# unless asked for with `--all`, `-m ""` or `-m oracle` etc.  Keyed by the path under tests/ and
# the test function's name; a whole module is named by its path alone (tests/test_tiers.py checks
# that every name here is a test that exists).
TIERS: dict[str, dict[str, tuple[str, ...] | None]] = {
    # runs LinuxCNC's rs274 or FreeCAD, oracles ncpp did not write
    "oracle": {
        "shop/test_post_cycles.py": (
            "test_compensated_holes_stay_where_programmed_with_the_pipeline_warning",
            "test_creo_deep_holes_are_drilled_to_their_depth_in_rs274",
            "test_nx_holes_reach_their_bottoms_and_retract_as_the_records_say",
            "test_rs274_dwells_where_the_cl_data_delays",
            "test_the_holes_moves_compensation_sees_are_the_ones_rs274_makes",
        ),
        "compensation/test_rs274_accepts.py": None,
        "compensation/test_periodic_errors.py": None,
        "compensation/test_rotary_increments.py": None,
        "motion/test_centre_path.py": ("test_the_tool_centre_runs_where_rs274_puts_it",),
        "writeback/test_subroutines_run_once.py": None,
        "compensation/test_subprograms_first.py": None,
        "writeback/test_haas_local_subprograms.py": None,
        "motion/test_haas_local_calls.py": ("test_the_moves_are_rs274s_of_the_program_written_out_by_hand",),
        "compensation/test_machine_files.py": (
            "test_compensated_programs_land_on_the_path_on_each_machine",
            "test_reversal_tables_of_both_signs_are_compensated_for_the_direction_travelled",
            "test_a_run_of_g91_increments_does_not_drift_by_their_roundings",
        ),
        "compensation/test_additional_offsets.py": (
            "test_each_move_is_compensated_where_its_system_puts_it",
        ),
        "compensation/test_lathe.py": ("test_linuxcncs_g92_s_is_refused_in_rs274s_words",),
        "compensation/test_rotation.py": (
            "test_the_whole_path_under_g10_l2_r_lands_on_the_original_in_rs274",
            "test_the_interpreter_follows_rs274_through_offsets_changed_under_a_rotation",
            "test_the_whole_path_under_g68_lands_on_the_original_in_rs274",
            "test_a_parameter_files_rotation_is_followed_as_rs274_follows_it",
        ),
        "compensation/test_rotation_planes.py": (
            "test_the_whole_path_under_g68_in_g18_and_g19_lands_on_the_original_in_rs274",
        ),
        "compensation/test_mirror.py": (
            "test_the_whole_path_under_g51_1_lands_on_the_original_in_rs274",
            "test_cutter_compensation_under_g51_1_lands_on_the_original_in_rs274",
        ),
        "compensation/test_rotated_cutter_comp.py": (
            "test_g41_under_g10_l2_r_passes_pathcheck_at_twice_the_largest_correction",
            "test_g41_under_g68_lands_on_the_original_in_rs274_written_as_linuxcncs_g10_l2_r",
        ),
        "compensation/test_rigid_tap.py": (
            "test_each_tap_runs_on_the_programmed_line_within_half_a_micron",
            "test_the_motor_mount_written_out_cuts_twenty_times_closer",
        ),
        "compensation/test_cutter_comp_accuracy.py": (
            "test_the_tool_centre_lands_on_the_original_path_within_half_a_micron",
            "test_a_corner_turned_right_back_is_verified_as_the_control_makes_it",
            "test_in_g18_and_in_g91_the_tool_centre_lands_on_the_original_path",
            "test_with_expand_the_moves_under_compensation_in_loops_and_subroutines_land_on_the_path",
            "test_the_entry_arc_stays_one_arc_the_control_accepts",
            "test_mmount_contours_land_within_the_tolerance",
            "test_a_move_along_z_alone_under_compensation_makes_no_move_in_the_plane",
        ),
        "motion/test_oracle.py": None,
        "compensation/test_tool_parameters.py": (
            "test_an_inch_machine_reads_the_spindle_tools_entry_as_rs274_does",
            "test_an_mm_machine_reads_the_table_in_mm_as_rs274_reads_its_inches",
            "test_written_out_the_pocket_sized_by_the_diameter_lands_on_the_original",
        ),
        "compensation/test_program_tool_offsets.py": (
            "test_g10_l1_l10_l11_set_the_offsets_rs274_applies_at_the_next_g43",
            "test_rs274_and_ncpp_refuse_the_same_g10",
            "test_the_abbe_arm_is_compensated_at_the_length_the_program_sets",
            "test_pathcheck_passes_the_output_with_the_lengths_the_program_sets",
        ),
        "motion/test_fanuc_files.py": (
            "test_the_moves_are_rs274s_of_the_twin_with_the_subprogram_in_the_first_program",
            "test_expanded_the_calls_follow_rs274s_path_of_the_twin",
            "test_subprograms_before_the_main_program_run_where_it_calls_them_as_rs274_runs_the_twin",
        ),
        "hostile/test_constructs.py": ("test_rs274_refuses_a_modal_rigid_tap_block_without_its_k",),
        "shop/test_tool_guard.py": (
            "test_rs274_runs_the_program_with_the_told_table_and_stops_at_a_length_that_differs",
            "test_rs274_stops_before_the_first_cut_that_reads_a_diameter_that_differs",
        ),
        "shop/test_g92_guard.py": (
            "test_rs274_runs_a_touched_off_program_where_the_tool_stands_at_the_zero_told_whatever_the_work_offset",
            "test_rs274_runs_a_g10_l20_touch_off_under_another_g92_offset_with_the_tool_at_the_zero_told",
            "test_rs274_runs_a_program_that_selects_its_system_then_touches_off_whatever_that_system_s_zero",
            "test_rs274_checks_only_the_axes_the_program_had_not_positioned",
            "test_rs274_checks_an_offset_set_under_a_g92_offset_of_the_parameter_file",
            "test_rs274_checks_the_offset_a_g92_3_restores",
            "test_the_interpreter_applies_the_saved_offset_at_g92_3_as_rs274_does",
            "test_rs274_checks_the_zero_of_the_system_p_names_on_the_axes_not_positioned",
        ),
        "shop/test_guard.py": (
            "test_rs274_stops_the_guarded_program_where_g54_is_turned_other_than_told",
            "test_rs274_runs_a_program_that_selects_its_system_whatever_system_the_control_was_left_in",
            "test_rs274_stops_a_program_before_a_system_it_selects_later_whose_zero_moved",
        ),
        "writeback/test_compensated_holes.py": None,
        "writeback/test_compensated_back_bore.py": (
            "test_each_back_bore_cuts_to_its_top_and_stands_at_its_bottom_and_r",
            "test_fanuc_back_bores_cut_to_their_top_and_start_at_their_r",
        ),
        "writeback/test_expand_cycles.py": ("test_expanded_cycles_dwell_as_programmed_and_hit_every_hole",),
        "writeback/test_expand_flow.py": (
            "test_expanded_bodies_land_where_programmed_and_rs274_runs_the_same_path",
            "test_expanded_fanuc_macros_move_as_rs274_runs_their_o_word_twins",
            "test_expanded_offsets_and_cycles_run_in_rs274_as_the_original",
            "test_debug_messages_show_each_runs_values_as_rs274_shows_the_originals",
            "test_corpus_programs_with_loops_expanded_run_in_rs274_as_the_originals",
            "test_the_corpus_mount_program_expanded_runs_in_rs274_as_the_original",
        ),
        "motion/test_fanuc_macro.py": (
            "test_fanuc_macros_move_as_rs274_runs_their_o_word_twins",
            "test_random_fanuc_macros_move_as_rs274_runs_their_o_word_twins",
            "test_a_cycle_of_l0_stores_its_data_for_the_holes_a_subprogram_gives",
            "test_holes_after_a_cycle_of_l0_in_straight_code_are_compensated",
        ),
        "property/test_cutter_comp_properties.py": None,
        "shop/test_freecad_post.py": None,
        "compensation/test_tool_lengths.py": (
            "test_tool_lengths_agree_with_linuxcnc_started_from_the_same_tool_table",
        ),
        "compensation/test_work_offsets.py": (
            "test_placement_agrees_with_linuxcnc_started_from_the_same_parameter_file",
        ),
        "motion/test_corner_rounding.py": ("test_compensated_corners_are_plain_arcs_linuxcnc_accepts",),
        "motion/test_fanuc_flavours.py": (
            "test_a_program_number_written_with_a_colon_is_the_o_number",
            "test_g0_in_a_return_block_is_the_modal_motion_after_it",
            "test_haas_peck_holes_are_rs274s_of_the_cycle_without_p",
            "test_an_r_arc_that_ends_where_it_starts_passes_through_and_rs274_judges_the_rest",
            "test_r_wins_over_i_j_k_in_a_fanuc_arc_block",
            "test_a_haas_circular_pocket_passes_through_and_the_moves_before_it_are_compensated",
            "test_a_fanuc_tool_position_offset_passes_through_and_the_moves_before_it_are_compensated",
            "test_a_fanuc_h_word_without_g43_passes_through_and_the_moves_before_it_are_compensated",
            "test_g80_leaves_the_motion_mode_the_cycle_interrupted",
            "test_the_moves_before_any_motion_code_are_rs274s_of_the_twin_that_writes_g0_in_them",
            "test_the_moves_before_any_motion_code_are_written_as_programmed_and_the_rest_compensated",
            "test_a_linuxcnc_or_is_a_truth_value_as_rs274_reads_it",
        ),
        "writeback/test_loops_run_once.py": (
            "test_a_body_that_runs_once_is_compensated_in_place",
            "test_a_loop_that_runs_twice_stays_as_programmed_inside_one_that_runs_once",
        ),
        "writeback/test_last_line_unended.py": ("test_rs274_reads_the_output_as_the_input_within_20_um",),
        "writeback/test_expression_word_spelling.py": (
            "test_the_g43_move_gains_its_x_once_and_rs274_runs_the_path",
        ),
        "motion/test_haas_kept_variables.py": (
            "test_a_timer_kept_in_a_variable_leaves_the_moves_compensated",
        ),
        "motion/test_zero_feed.py": ("test_a_feed_move_at_a_zero_feed_is_refused_where_rs274_refuses_it",),
        "motion/test_cutter_comp.py": (
            "test_ncpp_motion_prints_the_tool_centre_as_rs274_does",
            "test_simulate_samples_the_tool_centre_where_rs274_runs_it",
            "test_g41_checks_against_the_radius_of_the_tool_table_ncpp_is_told",
            "test_moves_after_compensation_agree_with_rs274",
            "test_refused_with_compensation_as_rs274_refuses",
            "test_rs274_runs_the_compensated_program_with_the_same_moves_under_compensation",
        ),
        "motion/test_cycles.py": (
            "test_cycles_move_as_rs274_does",
            "test_cycles_refused_where_rs274_refuses",
            "test_random_cycle_programs_agree_with_rs274",
            "test_rs274_accepts_the_compensated_cycles",
            "test_rs274_taps_in_g18_and_g19_feed_other_axes",
        ),
        "motion/test_flow.py": (
            "test_flow_moves_as_rs274_does",
            "test_flow_refused_where_rs274_refuses",
            "test_random_flow_programs_agree_with_rs274",
            "test_rs274_runs_the_compensated_program_with_the_same_subroutine_moves",
            "test_subroutine_files_move_as_rs274_does",
        ),
        "motion/test_polar.py": (
            "test_polar_programs_agree_with_rs274",
            "test_rs274_runs_the_compensated_polar_program",
        ),
        "passes/test_compensate_cli.py": ("test_linuxcnc_accepts_every_compensated_arc",),
        "shop/test_linuxcnc_filter.py": (
            "test_axis_filters_a_long_program_with_its_progress_bar",
            "test_axis_loads_the_program_the_filter_compensated",
            "test_axis_shows_the_filters_error_and_loads_nothing",
            "test_filter_compensates_reports_progress_and_rs274_accepts_it",
        ),
        "shop/test_post.py": (
            "test_linuxcnc_runs_the_post_to_the_cl_end_points",
            "test_posted_with_a_machine_file_is_compensated",
        ),
    },
    # a second and a half or more on a 2-core machine, all parameters together
    "slow": {
        "compensation/test_periodic_errors.py": None,
        "compensation/test_rotary_increments.py": None,
        "motion/test_fanuc_read_ahead.py": ("test_past_the_read_ahead_the_compensated_text_is_the_same",),
        "compensation/test_tool_parameters.py": (
            "test_written_out_the_pocket_sized_by_the_diameter_lands_on_the_original",
        ),
        "shop/test_tool_guard.py": ("test_compensated_again_the_read_checks_go_with_a_warning",),
        "dialect_motion/test_heidenhain_corners.py": (
            "test_compensated_klartext_has_explicit_arcs_and_consistent_numbers",
        ),
        "writeback/test_expand_cycles.py": ("test_both_commands_take_the_option",),
        "compensation/test_rotation_dialects.py": (
            "test_the_verifier_refuses_a_writer_that_gets_the_rotation_wrong",
            "test_the_programmed_points_are_reached_under_a_rotation_within_half_a_micron",
        ),
        "compensation/test_several_programs.py": ("test_one_process_does_the_same",),
        "compensation/test_rotation.py": (
            "test_the_verifier_refuses_a_writer_that_gets_the_rotation_wrong",
            "test_the_programmed_points_are_reached_under_g68_within_half_a_micron",
            "test_a_g68_of_variables_turns_as_their_values_do",
            "test_a_g69_among_modes_of_other_groups_is_followed",
            "test_a_safety_lines_cancels_of_modes_not_in_effect_change_nothing",
        ),
        "compensation/test_rotation_planes.py": (
            "test_the_verifier_refuses_a_writer_that_gets_a_g18_rotation_wrong",
            "test_the_programmed_points_are_reached_under_g68_in_g18_and_g19_within_half_a_micron",
            "test_the_first_move_ncpp_rewrites_after_a_g18_rotation_gives_both_of_its_axes",
        ),
        "compensation/test_mirror.py": (
            "test_the_verifier_refuses_a_writer_that_gets_the_mirror_image_wrong",
            "test_the_programmed_points_are_reached_under_g51_1_within_half_a_micron",
        ),
        "shop/test_extents.py": None,  # (each runs the command line)
        "compensation/test_warning_order.py": None,
        "export/test_tables.py": None,
        "compensation/test_rotary_dialects.py": None,
        "motion/test_fanuc_flavours.py": (
            "test_a_fusion_drilling_program_with_axis_words_after_g80_is_compensated_as_fanuc",
            "test_a_program_with_g0_in_a_return_block_and_no_number_is_read_as_fanuc",
            "test_a_haas_peck_cycle_with_p_is_compensated_with_its_p_and_verified",
            "test_external_output_passes_through_the_compensated_program",
            "test_expand_keeps_a_g68_of_variables_out_of_scope",
            "test_a_g81_with_p_is_compensated_with_its_p_and_expand_cycles_refuses_it",
            "test_a_g91_move_before_any_motion_code_right_after_a_cycle_passes_the_rest_on",
        ),
        "compensation/test_cutter_comp_accuracy.py": (
            "test_a_z_move_under_compensation_keeps_the_tool_centre_where_it_stands",
            "test_mmount_contours_land_within_the_tolerance",
        ),
        "compensation/test_rigid_tap.py": (
            "test_a_tap_rs274_refuses_is_refused",
            "test_a_machine_with_reversal_errors_gets_no_step_inside_a_tap",
            "test_the_motor_mount_written_out_cuts_twenty_times_closer",
            "test_a_tap_ncpp_cannot_follow_passes_through",
        ),
        "hostile/test_dialect_errors.py": (  # (each case runs the command line)
            "test_fn_functions_of_a_valid_tnc_program_are_read",
            "test_a_sinumerik_function_of_the_wrong_arity_is_a_located_error",
        ),
        "hostile/test_line_counts.py": ("test_continued_klartext_lines_are_counted_as_lines",),
        "writeback/test_expression_axes.py": ("test_expression_axis_keeps_its_correction",),
        "writeback/test_cycle_start.py": ("test_cycle_holes_where_the_program_puts_them",),
        "hostile/test_resources.py": (
            "test_compensating_a_loop_takes_the_same_memory_however_often_it_runs",
            "test_a_loop_run_once_around_one_run_often_takes_bounded_memory",
        ),
        "writeback/test_last_line_unended.py": ("test_the_lines_written_for_an_unended_last_line_each_end",),
        "cldata/test_cldata.py": ("test_corpus_file_reads_and_moves_where_the_gotos_say",),
        "compensation/test_lathe.py": ("test_no_program_of_the_corpus_is_taken_for_a_lathe_program",),
        "identify/test_thesis_sample.py": ("test_make_reproduces_the_committed_comparison",),
        "diagnose/test_diagnose.py": ("test_one_hidden_effect_is_named_sized_and_closes_the_gap",),
        "shop/test_plots.py": (
            "test_simulate_plot_draws_the_contour_error_along_the_path_and_a_map_coloured_by_it",
        ),
        "dialects/test_written_apart.py": ("test_as_round_says",),
        "dialect_motion/test_heidenhain_patterns.py": (
            "test_the_command_line_compensates_around_a_pattern_and_verifies_it_on_the_wide_machine",
        ),
        "dialect_motion/test_heidenhain_pattern_positions.py": (
            "test_the_command_line_writes_the_corrected_pattern_and_warns_once_for_the_call",
        ),
        "dialect_motion/test_sinumerik_patterns.py": (
            "test_the_command_line_compensates_around_holes1_and_holes2_on_the_wide_machine",
        ),
        "passes/test_compensate_cli.py": (
            "test_an_arc_of_more_turns_than_compensation_holds_is_refused_with_its_line",
            "test_simulate_refuses_motion_outside_the_travel_and_paths_past_its_sample_budget",
            "test_contour_error_shrinks_on_the_virtual_machine",
            "test_second_compensation_is_refused_unless_forced",
        ),
        "benchmarks/test_harness.py": (
            "test_a_timed_run_in_a_fresh_process",
            "test_programs_compensated_across_processes_are_timed_and_counted",
        ),
        # the fast tier's slowest (command-line runs of a second or more each)
        "motion/test_fanuc_macro.py": (
            "test_memory_stays_flat_with_fanuc_loops",
            "test_a_program_with_a_cycle_of_l0_is_compensated_and_steps_back_before_it",
        ),
        "compensation/test_work_offsets.py": ("test_command_line_var_file_and_work_offsets_say_the_same",),
        "compensation/test_tool_lengths.py": ("test_command_line_tool_table",),
        "compensation/test_placement.py": (
            "test_fusion_g28_retract_is_left_to_the_control",
            "test_the_impeller_compensates_on_a_machine_whose_xyz_are_axis_positions",
            "test_moves_after_a_return_are_corrected_from_the_home_position",
        ),
        "verify/test_verifier.py": ("test_a_path_over_itself_too_often_is_refused_with_a_way_out",),
        "compensation/test_machine_files.py": (
            "test_compensated_programs_land_on_the_path_on_each_machine",
            "test_simulate_runs_a_program_on_a_machine_whose_travel_does_not_hold_zero",
            "test_a_run_of_klartext_increments_does_not_drift_by_their_roundings",
        ),
        "dialect_motion/test_subprogram_calls.py": (
            "test_sinumerik_long_runs_are_written_and_verified_a_chunk_at_a_time",
            "test_klartext_long_runs_are_written_and_verified_a_chunk_at_a_time",
        ),
        "writeback/test_expand_flow.py": (
            "test_both_commands_take_the_option_and_refuse_with_the_place",
            "test_the_corpus_mount_program_expanded_runs_in_rs274_as_the_original",
            "test_corpus_programs_with_loops_expanded_run_in_rs274_as_the_originals",
        ),
        "shop/test_linuxcnc_filter.py": (
            "test_without_machine_file_the_program_loads_unchanged",
            "test_the_parameter_file_places_the_program_as_linuxcnc_does",
            "test_the_configuration_linuxcnc_runs_gives_its_parameter_file_and_tool_table",
            "test_a_compensated_program_is_not_compensated_again",
            "test_the_tool_table_gives_the_lengths_g43_applies",
        ),
        "shop/test_guard.py": (
            "test_the_guard_is_written_only_where_the_offset_was_told_and_not_with_no_guard",
            "test_the_post_writes_the_guard_of_its_dialect",
            "test_a_sinumerik_program_gets_its_settable_frame_checked_and_ncpp_still_reads_it",
            "test_rs274_runs_the_guarded_program_where_g54_matches_and_stops_it_where_not",
        ),
        "hostile/test_fuzz.py": ("test_fuzzed_inputs_are_refused_located_in_bounded_time_and_memory",),
        "hostile/test_killed.py": (
            "test_a_killed_run_leaves_no_file_beside_its_output",
            "test_a_new_output_file_takes_its_mode_from_the_umask",
        ),
        "hostile/test_endless_loops.py": (
            "test_the_command_refuses_a_loop_back_at_a_state_it_had_in_seconds",
        ),
        "hostile/test_counted_loops.py": (
            "test_a_counted_loop_past_the_bound_is_refused_at_its_line_at_once",
            "test_a_loop_of_a_hundred_thousand_passes_still_runs",
            "test_a_counted_loop_around_a_subprograms_repeated_runs_is_refused_at_its_line_at_once",
            "test_subprogram_runs_that_stay_under_the_bound_run_to_their_end",
        ),
        "hostile/test_many_turns.py": (
            "test_an_arc_of_more_chords_than_the_verifier_holds_is_refused_at_its_line",
            "test_an_arc_of_ten_thousand_turns_is_compensated_in_bounded_memory",
        ),
        "hostile/test_huge_numbers.py": ("test_a_tool_1e308_mm_long_is_refused_without_a_numpy_warning",),
        "hostile/test_constructs.py": (
            "test_a_cycle_left_as_programmed_far_past_any_travel_is_verified_in_bounded_memory",
            "test_holes_of_a_modal_cycle_far_past_any_travel_are_refused_in_bounded_memory",
            "test_an_arc_round_a_centre_far_past_any_travel_is_refused_in_bounded_memory",
        ),
        "motion/test_fanuc_files.py": (
            "test_a_subprogram_file_named_for_its_number_without_the_o_is_found",
            "test_the_text_after_the_closing_percent_passes_through_as_it_is",
            "test_where_the_main_program_is_not_told_the_file_passes_through_and_strict_refuses",
        ),
        "hostile/test_cli_contained.py": (
            "test_an_open_subroutine_is_located",
            "test_a_terminated_run_removes_its_temporaries",
            "test_a_subroutine_name_stays_inside_the_subroutine_path",
        ),
        "hostile/test_parser_limits.py": (
            "test_fifty_megabytes_of_one_line_are_refused_in_bounded_time",
            "test_a_million_brackets_are_refused_in_a_second",
        ),
        "instruments/test_analyze_cli.py": ("test_plot_writes_a_png_for_every_kind",),
        "shop/test_summary.py": (
            "test_the_summary_is_on_stderr_without_a_terminal_and_in_the_report",
            "test_compensate_and_simulate_find_the_machine_file_as_ncpp_does",
        ),
        "motion/test_flow.py": (
            "test_compensate_with_a_subroutine_path",
            "test_memory_stays_flat_around_loops_and_calls",
        ),
        "motion/test_cutter_comp.py": (
            "test_motion_and_simulate_say_where_the_tool_leaves_the_programmed_contour",
        ),
        "dialects/test_corpus.py": ("test_cli_dialect_option_overrides_and_errors_name_the_line",),
        "compensation/test_parsed_ahead.py": (
            "test_runs_of_any_length_write_what_one_line_at_a_time_writes",
        ),
        "program/test_layout_replay.py": ("test_replay_agrees_with_the_lalr_parser_on_corpus",),
        "program/test_roundtrip.py": (
            "test_corpus_program_roundtrips_byte_for_byte",
            "test_cli_error_has_location_no_traceback_and_no_output",
            "test_cli_passthrough_is_byte_identical",
            "test_fast_path_agrees_with_lalr_parser_on_corpus",
        ),
        "property/test_parser_properties.py": (
            "test_generated_programs_parse_to_their_word_values_and_roundtrip",
        ),
        "shop/test_post.py": ("test_every_cl_file_posts_in_every_dialect",),
        "shop/test_freecad_base.py": None,
        "shop/test_post_cycles.py": ("test_the_post_command_drills_the_creo_holes",),
        "shop/test_shipped.py": (
            "test_install_freecad_post_from_the_wheel",
            "test_the_wheel_finds_its_samples_and_plugins_inside_the_package",
        ),
        "shop/test_shop_pipeline.py": (
            "test_any_error_stops_the_pipeline",
            "test_machine_from_the_local_config_compensates",
        ),
        "compensation/test_non_finite.py": ("test_a_tolerance_of_1e_300_subdivides_as_finely_as_1e_30",),
        "compensation/test_exact_model.py": (
            "test_reversal_spots_within_tolerance",
            "test_contour_error_within_tolerance",
        ),
        "program/test_writer.py": (
            "test_a_letter_is_written_in_the_style_of_its_last_number",
            "test_the_styles_kept_resolved_are_those_the_styles_learnt_resolve_to",
            "test_planned_lines_are_the_general_lines",
            "test_sinumerik_lines_by_plans_and_templates_are_the_general_ones",
        ),
        "interop/test_pygcode.py": (
            "test_word_values_agree_with_pygcode_on_corpus",
            "test_block_to_pygcode_and_back_keeps_every_word_value",
        ),
        "identify/test_ballbar_fit.py": (
            "test_fit_and_predict_commands_with_ballbar_files",
            "test_fit_explains_the_files_to_the_noise",
            "test_a_laser_file_of_one_axis_fixes_the_scale_and_the_comparator_follows",
        ),
        "compensation/test_dialect_tool_lengths.py": (
            "test_command_line_tool_table",
            "test_motion_and_simulate_take_the_dialect_and_its_tool_table",
        ),
        "motion/test_haas_kept_variables.py": None,
        "motion/test_zero_feed.py": None,
        "verify/test_pipeline_verifies.py": (
            "test_a_long_loop_is_verified_a_chunk_at_a_time",
            "test_a_written_loop_that_runs_once_less_is_refused",
        ),
        "writeback/test_klartext_once.py": (
            "test_a_run_written_where_it_runs_and_at_its_text_is_refused_by_the_verifier",
        ),
    },
    # runs ncpp in two processes (a test parametrized with jobs >= 2 is one too)
    "multiprocess": {
        "compensation/test_several_programs.py": (
            "test_two_processes_write_each_program_as_its_own_run_does_and_report_the_one_that_fails",
        ),
        "hostile/test_killed.py": ("test_the_workers_of_a_killed_run_stop_with_it",),
    },
}


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--all", action="store_true", help="run every tier: slow, oracle and multi-process tests too"
    )


def pytest_configure(config: pytest.Config) -> None:
    if config.getoption("--all"):
        config.option.markexpr = ""  # overrides the tier selection in pyproject's addopts
    _home_of_its_own()


def _home_of_its_own() -> None:
    """A $HOME of the test run's own: rs274 keeps its tool data in $HOME/.tool.mmap, which another
    rs274 running meanwhile (another test run, a user's) rewrites under it (wrong tool offsets, a bus
    error).  The unpacked rs274 and ncpp's parser cache stay where they are."""
    real = Path.home()
    os.environ.setdefault("RS274_HOME", str(real / ".cache" / "ncpp-rs274"))
    os.environ.setdefault("XDG_CACHE_HOME", str(real / ".cache"))
    home = Path(tempfile.mkdtemp(prefix="ncpp-tests-home-"))
    atexit.register(shutil.rmtree, home, ignore_errors=True)
    os.environ["HOME"] = str(home)


def tiers_of(item: pytest.Item) -> set[str]:
    """The tiers a collected test belongs to, by TIERS and its `jobs` parameter."""
    module = Path(str(item.path)).relative_to(Path(__file__).parent).as_posix()
    name = getattr(item, "originalname", item.name)
    found = set()
    for tier, modules in TIERS.items():
        if module in modules and (modules[module] is None or name in modules[module]):
            found.add(tier)
    jobs = item.callspec.params.get("jobs") if hasattr(item, "callspec") else None
    if isinstance(jobs, int) and jobs > 1:
        found.add("multiprocess")
    return found


@pytest.hookimpl(tryfirst=True)  # before `-m` deselects by the markers
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        for tier in tiers_of(item):
            item.add_marker(tier)


def corpus_files(*folders: str) -> list[Path]:
    """Program files under the given corpus folders, sorted, oracles and hidden files (a tool's
    `.tool.mmap` left by an rs274 run there) excluded."""
    found: list[Path] = []
    for folder in folders:
        for path in sorted((CORPUS / folder).rglob("*")):
            if (
                path.is_file()
                and not path.name.startswith(".")
                and not any(path.name.endswith(s) or s in path.name for s in NOT_PROGRAMS)
            ):
                found.append(path)
    return found


def corpus_id(path: Path) -> str:
    return str(path.relative_to(CORPUS))


@pytest.fixture(scope="session")
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip(f"corpus not found at {CORPUS}")
    return CORPUS


def expected_signature(items) -> str | None:
    """`Block.signature` of a plain line's items: its word letters in order, each G word
    with its number as written; None when a word has two letters (`,R`)."""
    from ncpp.program.blocks import Word

    words = [i for i in items if type(i) is Word]
    if any(len(w.letter) > 1 for w in words):
        return None
    return "".join(w.letter + w.number * (w.letter == "G") for w in words)
