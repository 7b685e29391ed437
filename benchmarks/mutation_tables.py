"""Per-mutant tables of ``python -m benchmarks.mutation``: the equivalent mutants
with the reason, the test that kills each survivor of a fresh sample, the survivors renamed in
today's code, and the survivors neither killed nor shown equivalent with why."""

from __future__ import annotations

# mutant name -> why it is equivalent (no observable change); filled in from the survivors
EQUIVALENT: dict[str, str] = {
    "rtsgeom.calibration.fit.x_fit_centre__mutmut_43":
        "np.asarray(extra_phase_rad) without float: the callers pass the probes' phases as "
        "float arrays already; the same array.",
    "rtsgeom.synthesis.model.xǁChannelModelǁcoherent_phases__mutmut_32":
        "a zero-magnitude product divided by 2.0 instead of 1.0: it is zero either way, so the "
        "same sum and angle.",
    "rtsgeom.radar.newton.x_newton__mutmut_156":
        "a non-finite Hessian entry replaced by 1.0 instead of 0.0 before its eigenvalues are "
        "taken: such a row is not concave whatever they are (the test is ANDed with all "
        "entries finite), so the same step.",
    "rtsgeom.analysis.kpi.report.x__stack__mutmut_5":
        "FigureCanvasAgg(None) instead of FigureCanvasAgg(page): the page keeps matplotlib's "
        "default canvas, and saving it to PDF or PNG switches to that format's canvas either "
        "way (the Agg canvas was set only to draw it in memory); the same bytes.",
    "rtsgeom.rts.fir.x__fir_rows__mutmut_80":
        "every setting treated as a memo miss: its rows are computed again, by the same "
        "elementwise arithmetic, and looked up at the first of the equal settings; the memo "
        "fills and restarts sooner (time only), the returned rows are the same bits.",
    "rtsgeom.geometry.arrays.x__grid_unit__mutmut_5":
        "np.asarray(x) instead of np.asarray(x, float): every caller passes float positions "
        "(metres), so the array is the same.",
    "rtsgeom.geometry.arrays.x_posed_positions__mutmut_3":
        "np.asarray(yaw, None) instead of float: a yaw offset is a float or a float array, the "
        "array is the same (and cos/sin make floats of any integer).",
    "rtsgeom.geometry.sheet.x_sheet_mesh__mutmut_29":
        "np.asarray(angles) without float: the cutout angles are floats (radians) already.",
    "rtsgeom.geometry.farfield.x_coarray_period_m__mutmut_1":
        "the default search depth 64 -> 65 differs only for an array whose co-array period is "
        "d_min/65; the scene selects presets only (periods d_min or d_min/2), custom arrays "
        "are not wired to the scene.",
    "rtsgeom.geometry.patterns.x_direction_angles__mutmut_16":
        "no lower clip for arcsin(v_z / |v|): the ratio of a component to the norm lies in "
        "[-1, 1] (exactly -1 straight down); only a rounding past -1 could differ.",
    "rtsgeom.radar.dca1000.x_to_dca1000__mutmut_48":
        "the I part rounded to float64 instead of int16 before `.astype('<i2')`: the values "
        "are whole numbers within int16, so the bytes are the same.",
    "rtsgeom.radar.steering.xǁSteeringǁsearch__mutmut_60":
        "the zoom grid loses its last point (+half): the coarse peak is within half a coarse "
        "step (0.125 deg < 0.3 deg; 0.0025 deg < 0.006 deg) of the grid centre, so the "
        "argmax never falls on that point.",
    "rtsgeom.radar.steering.xǁSteeringǁsearch__mutmut_4":
        "the error message gains 'XX' around the same text (the test matches the text).",
    "rtsgeom.analysis.tolerance.driver.x_evaluate_chunk__mutmut_59":
        "np.take_along_axis without axis= uses axis=-1 in numpy 2, the axis given.",
    # fresh sample (seed 3)
    "rtsgeom.calibration.pair.x_frames_per_step__mutmut_23":
        "dead code: aoa.calibration.frames_per_step is called nowhere (the calibration sizes its "
        "frames per step by a Monte-Carlo of the phasor model since), so no output can change.",
    "rtsgeom.calibration.pair.x_frames_per_step__mutmut_80":
        "dead code: frames_per_step is called nowhere (see mutmut_23).",
    "rtsgeom.calibration.pair.x_frames_per_step__mutmut_86":
        "dead code: frames_per_step is called nowhere (see mutmut_23).",
    "rtsgeom.analysis.design.x__fit_sheet__mutmut_38":
        "a redundant guard: the scene rules (scene_rules: rx_tx_separation_m < "
        "cutout_diameter_m, |antenna offset| < cutout_diameter_m / 2) reject every scene in "
        "which 'max antenna offset >= d/2' could hold, and two_front_end_scene keeps the "
        "layout and the cutout; the clause is false before and after (0.5 / d is 10 m).",
    "rtsgeom.analysis.ghosts.x__peak__mutmut_19":
        "the +-1-bin window around a predicted echo keeps row -1 unclipped only when the echo "
        "is in range bin 0; the extra row is the last range bin, which the target range rule "
        "keeps k_r bins clear of any echo, and the echo itself (bin 0 or 1) is in the window "
        "either way, so the window's maximum is the same cell.",
    "rtsgeom.geometry.arrays.x__to3__mutmut_5":
        "np.asarray(xz) without float: np.stack with np.zeros (float64) promotes integer "
        "positions to float64 anyway; same array.",
    "rtsgeom.geometry.arrays.x_array_from_spec__mutmut_14":
        "meshgrid with indexing='xy' over (slots, [0], rx) swaps the first two axes, one of "
        "which has length 1: the raveled slot and rx indices are in the same order.",
    "rtsgeom.geometry.farfield.x_smallest_spacing_m__mutmut_10":
        "float('INF') is float('inf').",
    "rtsgeom.geometry.patterns.xǁTablePatternǁfrom_samples__mutmut_42":
        "np.asarray(phase_deg) without float: np.radians returns float64 for integer input; "
        "same table.",
    "rtsgeom.radar.steering.xǁSteeringǁ_search_2d__mutmut_41":
        "the coarse start of the 2-D search ranks grid points by re^3 + im^2 instead of the "
        "power: Steering.peak checks every Newton result against the grid's power maximum and "
        "restarts from that maximum when the start led elsewhere, so only the number of "
        "Newton steps changes (test_2d_search_is_independent_of_the_targets_phase passes "
        "under it to 1e-6 deg with the target's phase all around the circle).",
    "rtsgeom.radar.steering.x__newton__mutmut_250":
        "axis=+1 instead of -1 on u of shape (n, D): the same axis.",
    "rtsgeom.calibration.sweep.x_design_ratio__mutmut_128":
        "code replaced since the sample: P'' = 2 Re(s* s2) + 2 |s1|^2 is now written per "
        "coefficient in ratio_from_beams (re(bi1, bi1) + ...), the mutated line no longer "
        "exists (mutmut generates no such mutant). Before that it survived every setup tried "
        "(|s1| is nearly 0 at the designed root), unproven; listed here as code that is gone.",
    # second fresh sample (seed 4)
    "rtsgeom.analysis.ghosts.x__unit_echoes__mutmut_43":
        "code replaced since the sample (the unit echoes are built by Echoes.build, which has "
        "no order argument); and equivalent before: order as float zeros instead of int "
        "zeros is only argsorted and read through int() by ghost_orders.",
    "rtsgeom.calibration.pair.x_frames_per_step__mutmut_26":
        "dead code, removed since the sample: frames_per_step was called nowhere (see "
        "mutmut_23 of the seed-3 sample).",
    "rtsgeom.calibration.pair.x_frames_per_step__mutmut_29":
        "dead code, removed since the sample (frames_per_step, see mutmut_26).",
    "rtsgeom.calibration.pair.x_frames_per_step__mutmut_70":
        "dead code, removed since the sample (frames_per_step, see mutmut_26).",
    "rtsgeom.calibration.pair.x_frames_per_step__mutmut_85":
        "dead code, removed since the sample (frames_per_step, see mutmut_26).",
    "rtsgeom.synthesis.nchannel.xǁChannelSetǁcoherent_phases__mutmut_27":
        "z / where(|z| > 0, |z|, 2) instead of 1: the fallback divides only where z = 0, and "
        "0 / 2 = 0 / 1 = 0; same sum.",
    "rtsgeom.calibration.sweep.x__noise_sigma__mutmut_2":
        "the unit program's delay None (NaN) instead of the probe's: _noise_sigma reads only "
        "the direct echoes' amplitudes, conj(g_a g_b G_q) (paths, programmed gain, hardware "
        "error), none of which depends on the programmed delay (the FIR's ripple is a "
        "separate fast_gain, unused here); same sigma.",
    "rtsgeom.calibration.sweep.x_phasor_sweep__mutmut_248":
        "np.stack of two 1-D arrays (S,) along axis +1 instead of -1: for the 2-D result "
        "(S, 2) both are axis 1; same array.",
    "rtsgeom.geometry.sheet.x_segments_blocked__mutmut_12":
        "np.asarray(end) without float: d = end - p0 with p0 float64 is float64 whatever "
        "the end points' dtype; same directions.",
    "rtsgeom.radar.processing.x__os_footprint__mutmut_27":
        "the OS-CFAR ring as float ones/zeros instead of bool: any(), flatnonzero and the "
        "thinning treat 0.0/1.0 as False/True, and scipy's percentile_filter casts the "
        "footprint to bool (np.asarray(footprint, dtype=bool)); same footprint.",
    # fresh sample (seed 11)
    "rtsgeom.identify.capture.x_read_capture__mutmut_108":
        "np.load(allow_pickle=None) instead of False: numpy tests `if not allow_pickle`, so "
        "None refuses an object array exactly as False does.",
    "rtsgeom.rts.fir.x_fir_taps__mutmut_31":
        "the (0, taps) table of an empty delay set as float instead of complex: the package's "
        "only caller (analysis/tolerance/tables.py) passes at least one echo, so the branch is "
        "dead for it, and an empty table contributes no row to any response.",
    # fresh sample (seed 23)
    "rtsgeom.analysis.coverage.x_coverage_designs__mutmut_79":
        "local_map(before_fork=None) instead of import_for_workers: the hook only imports the "
        "compiled kernels before a pool forks, so the workers inherit them instead of "
        "importing them each (~0.15 s CPU per worker); every design is computed the same "
        "either way (and with workers=1 no pool starts).",
    "rtsgeom.analysis.tolerance.cell.x_build_cell__mutmut_123":
        "the cell's response table one delay row longer at each end (z + 2 instead of z + 1): "
        "every row read is table_zero + sub-bin step + calibration step, at most "
        "max|sub| + max_steps = z - 1 from the centre, and np.gradient's slope at those rows "
        "is the central difference either way; the extra end rows are never read.",
    "rtsgeom.analysis.tolerance.cell.xǁCellProcedureǁcalibration_steps__mutmut_64":
        "np.take_along_axis without axis= uses axis=-1 in numpy 2 (2.4 here), the axis given "
        "(numpy 1.26, which pyproject still allows, would raise instead).",
    "rtsgeom.calibration.phasor.xǁSweepResultǁerrors__mutmut_1":
        "SweepResult.errors' default frames 1 -> 2: its three callers (phasor.py twice, "
        "steps.py) pass frames, so the default is never used.",
    "rtsgeom.radar.channels.x_rx_coupling_matrix__mutmut_44":
        "np.eye(n) as float instead of complex: adding complex(coefficient) * adj makes the "
        "sum complex128 with the same values (the coefficient is always a complex).",
    # seed 31 (found equivalent while writing its test, after the report)
    "rtsgeom.analysis.transfer.xǁTransferǁ_draw__mutmut_214":
        "the histogram's legend(fontsize=None) instead of 8: Transfer.plot draws inside "
        "rc_context(viz.figures.STYLE), whose legend.fontsize is 8, so the legend is the same.",
    # fresh sample (seed 37)
    "rtsgeom.analysis.objects.x_pairs__mutmut_33":
        "pairs' 'close' as float zeros instead of bool: the assigned comparisons store 1.0 / "
        "0.0, and its only reader (object_summary's reproduced_share) takes its mean, the same "
        "number; playback's reader uses the other return value.",
    "rtsgeom.rts.fir.x_fir_taps__mutmut_27":
        "the empty delay set's index array as float instead of int64: the branch is dead for "
        "the package, whose only caller passes at least one echo (as seed 11's "
        "fir_taps__mutmut_31).",
    "rtsgeom.synthesis.closed_form.x_closed_form_amplitudes__mutmut_59":
        "np.linalg.lstsq without rcond=None: numpy 2 (2.4 here) defaults rcond to None, the "
        "value given (numpy 1.26 warned and used -1 instead).",
    # seed 41 (a fourth fresh sample; no test written for it)
    "rtsgeom.geometry.setup.x_nominal_scene__mutmut_4":
        "every front end derived with its errors set to zero, also one without errors: the "
        "copy equals the front end (f.derive(errors = 0) == f for every error-free front end "
        "of the bundled scenes, field by field), so the nominal scene is the same; only the "
        "copy's cost differs (the comment's reason for keeping it).",
    "rtsgeom.radar.steering.x_smoothed_estimator__mutmut_3":
        "'bartlett' compared as 'XXbartlettXX': differs only for bartlett with "
        "angle_subarray > 0, which the scene's rules refuse (scene/rules.py: angle_subarray "
        "must be 0 with bartlett), and every caller passes a validated scene's radar values.",
    "rtsgeom.synthesis.batch.x_build_models__mutmut_166":
        "the steering argument ignored (always Steering.build(setup.rut, radar)): the "
        "package's only callers (pipeline/pair.py, twice) pass no steering, so the built one "
        "is what they get either way.",
}


# first-pass survivor -> the test that kills it (in the test file of the module it checks);
# the fresh sample (seed 3).
# Printed in the report's "killed by later tests" section.
KILLED_BY: dict[str, str] = {
    "rtsgeom.analysis.tolerance.arc.x_max_scale_for_yield__mutmut_56":
        "test_arc_yield_search_stops_at_zero_when_the_nominal_arc_fails",
    "rtsgeom.analysis.tolerance.arc.xǁBoundsǁfrom_tolerances__mutmut_65":
        "test_bounds_from_tolerances_scale_every_field",
    "rtsgeom.analysis.coverage.x_arc_scene__mutmut_14":
        "test_arc_scene_copies_the_first_front_end_without_its_errors",
    "rtsgeom.analysis.coverage.x_arc_scene__mutmut_20":
        "test_arc_scene_copies_the_first_front_end_without_its_errors",
    "rtsgeom.analysis.coverage.x_evaluate_arc__mutmut_149":
        "test_planned_arc_reports_the_outer_front_ends_near_field_bias",
    "rtsgeom.analysis.coverage.x_plan_arc__mutmut_179":
        "test_planned_arc_reports_the_outer_front_ends_near_field_bias",
    "rtsgeom.analysis.nearfield.x_synthesis_worst_errors_deg__mutmut_104":
        "test_nearfield_rows_and_exact_synthesis_on_the_nominal_setup",
    "rtsgeom.analysis.nearfield.x_synthesis_worst_errors_deg__mutmut_92":
        "test_nearfield_rows_and_exact_synthesis_on_the_nominal_setup",
    "rtsgeom.analysis.nearfield.xǁNearFieldǁ_row__mutmut_13":
        "test_nearfield_rows_and_exact_synthesis_on_the_nominal_setup",
    "rtsgeom.analysis.tolerance.driver.x_largest_passing_scale__mutmut_20":
        "test_largest_passing_scale_stops_when_the_bracket_is_within_rel_tol",
    "rtsgeom.analysis.tolerance.driver.x_monte_carlo__mutmut_69":
        "test_monte_carlo_without_draws_has_no_errors_and_no_yield",
    "rtsgeom.calibration.pair.x_calibrate_pair_paper__mutmut_171":
        "test_paper_procedure_reports_the_exact_period_at_its_target",
    "rtsgeom.calibration.pair.x_fir_effect__mutmut_146":
        "test_fir_effect_predicts_the_coherence_shift_in_picoseconds",
    "rtsgeom.synthesis.cells.x__interval__mutmut_29":
        "test_enclosing_interval_is_the_adjacent_pair_in_one_dimension",
    "rtsgeom.analysis.linearity.x__closed_form_measured__mutmut_37":
        "test_measured_end_angles_equal_geometric_ones_in_the_ideal_far_field",
    "rtsgeom.analysis.linearity2d.x_linearity_grid__mutmut_132":
        "test_2d_error_map_exact_mode_puts_every_grid_point_on_its_direction",
    "rtsgeom.analysis.linearity2d.x_linearity_grid__mutmut_170":
        "test_2d_error_map_exact_mode_puts_every_grid_point_on_its_direction",
    "rtsgeom.synthesis.model.xǁChannelModelǁair_legs__mutmut_59":
        "test_raising_the_rut_equals_lowering_every_front_end",
    "rtsgeom.calibration.channels.x_calibrate_channels__mutmut_36":
        "test_channel_calibration_of_one_channel_is_its_own_reference",
    "rtsgeom.calibration.channels.x_calibrate_pair_nd__mutmut_230":
        "test_nd_pair_calibration_lands_on_the_coherence_point",
    "rtsgeom.calibration.channels.x_calibrate_pair_nd__mutmut_264":
        "test_nd_pair_calibration_lands_on_the_coherence_point",
    "rtsgeom.calibration.channels.x_pair_edges__mutmut_23":
        "test_pair_edges_are_neighbours_in_1d_and_delaunay_edges_in_2d",
    "rtsgeom.calibration.channels.x_pair_edges__mutmut_27":
        "test_pair_edges_are_neighbours_in_1d_and_delaunay_edges_in_2d",
    "rtsgeom.synthesis.nchannel.x_closed_form_amplitudes__mutmut_44":
        "test_closed_form_amplitudes_ignore_a_common_phase",
    "rtsgeom.synthesis.nchannel.xǁChannelSetǁamplitudes__mutmut_4":
        "test_2d_error_map_exact_mode_puts_every_grid_point_on_its_direction",
    "rtsgeom.pipeline.plan.x_plan_targets__mutmut_88":
        "test_plan_reports_each_pairs_calibration_delay_in_picoseconds",
    "rtsgeom.calibration.sweep.x__noise_sigma__mutmut_78":
        "test_calibration_sweep_noise_is_the_adc_chains_within_a_factor_of_a_few",
    "rtsgeom.calibration.sweep.x_chain_errors__mutmut_45":
        "test_calibration_sweep_noise_is_the_adc_chains_within_a_factor_of_a_few (each seed "
        "its own noise)",
    "rtsgeom.calibration.sweep.x_fit_minimum__mutmut_22":
        "test_fit_minimum_finds_the_minimum_of_the_periodic_criterion_despite_lost_steps",
    "rtsgeom.identify.capture.x_read_capture__mutmut_96": "test_probe_capture_round_trip",
    "rtsgeom.radar.frame.x__simulate_linked__mutmut_64":
        "test_linked_frame_noise_is_the_receivers_thermal_noise_through_the_if_chain",
    # second fresh sample (seed 4)
    "rtsgeom.analysis.coverage.x_plan_arc__mutmut_17":
        "test_planned_arc_is_bound_by_resolution_when_the_fewest_front_ends_suffice",
    "rtsgeom.analysis.coverage.x_coverage_designs__mutmut_6":
        "test_coverage_designs_plan_every_radius_for_the_coverage_in_degrees",
    "rtsgeom.analysis.ghosts.x_measure_ghosts__mutmut_189":
        "test_strong_cable_ghosts_outside_the_cfar_window_are_reported_as_detected",
    "rtsgeom.calibration.pair.x_calibrate_pair__mutmut_207":
        "test_pair_calibration_places_its_probes_over_the_fine_window_and_reports_its_frames",
    "rtsgeom.calibration.pair.x_calibrate_pair__mutmut_245":
        "test_pair_calibration_places_its_probes_over_the_fine_window_and_reports_its_frames",
    "rtsgeom.calibration.pair.x_fir_effect__mutmut_134":
        "test_fir_effect_reports_its_filter_and_a_small_passband_ripple",
    "rtsgeom.calibration.pair.x_fir_effect__mutmut_5":
        "test_fir_effect_reports_its_filter_and_a_small_passband_ripple",
    "rtsgeom.calibration.channels.x_calibrate_channels__mutmut_71":
        "test_channel_calibration_depends_on_the_seed_modulo_2_to_the_32 (two channels: the "
        "tree's edges)",
    "rtsgeom.calibration.channels.x_calibrate_channels__mutmut_95":
        "test_channel_calibration_depends_on_the_seed_modulo_2_to_the_32 (two channels: the "
        "tree's edges)",
    "rtsgeom.calibration.channels.x__residual__mutmut_78":
        "test_channel_calibration_depends_on_the_seed_modulo_2_to_the_32",
    "rtsgeom.pipeline.plan.x_plan_targets__mutmut_161":
        "test_plan_record_says_where_its_calibration_came_from",
    "rtsgeom.pipeline.plan_cells.x_plan_cells__mutmut_153":
        "test_cell_plan_programs_the_doppler_of_each_targets_velocity",
    "rtsgeom.calibration.sweep.x_fit_minimum__mutmut_80":
        "test_fit_minimum_searches_the_half_width_it_is_given",
    "rtsgeom.geometry.setup.x_build_setup__mutmut_7":
        "test_rut_yaw_error_rotates_the_array_about_its_position",
    "rtsgeom.geometry.patterns.xǁPatternǁgain_db_towards__mutmut_5":
        "test_pattern_gain_db_is_twenty_log_of_the_field_and_finite_behind",
    "rtsgeom.identify.capture.x_read_capture__mutmut_78":
        "test_a_capture_that_is_not_a_complex_3d_cube_is_refused",
    "rtsgeom.radar.processing.x_detect__mutmut_76":
        "test_a_silent_cube_has_no_detections_and_empty_angles",
    "rtsgeom.radar.processing.xǁRangeDopplerǁto_xarray__mutmut_30":
        "test_a_silent_cube_has_no_detections_and_empty_angles",
    "rtsgeom.radar.steering.xǁSteeringǁpeak__mutmut_69":
        "test_unconverged_peaks_fall_back_to_the_search_and_the_others_keep_newton",
    "rtsgeom.rts.channels.x_channel_echoes__mutmut_36":
        "test_channel_echoes_pair_every_path_of_one_leg_with_every_path_of_the_other",
    # a seed-3 survivor, killed with the seed-4 tests
    "rtsgeom.radar.steering.xǁSteeringǁbuild__mutmut_16":
        "test_2d_steering_aperture_counts_distinct_positions_in_grid_units (grid unit lambda/16)",
    # seed 11
    "rtsgeom.analysis.design_study.xǁDesignStudyǁ__call____mutmut_23":
        "test_the_design_study_draws_with_its_seed_and_announces_its_count",
    "rtsgeom.analysis.design_study.xǁDesignStudyǁ__call____mutmut_90":
        "test_the_design_study_draws_with_its_seed_and_announces_its_count",
    "rtsgeom.analysis.kpi.study.xǁKpiStudyǁ__post_init____mutmut_7":
        "test_kpi_study_takes_three_sigmas",
    "rtsgeom.analysis.objects.x_clouds_csv__mutmut_18":
        "test_clouds_csv_writes_every_column_of_every_row",
    "rtsgeom.analysis.resolution.xǁResolutionStudyǁ__post_init____mutmut_149":
        "test_a_bad_separation_says_the_allowed_range",
    "rtsgeom.analysis.tolerance.study.xǁToleranceStudyǁ__post_init____mutmut_55":
        "test_a_bad_invert_yield_is_named",
    "rtsgeom.analysis.transfer.xǁTransferStudyǁ__post_init____mutmut_196":
        "test_a_transfer_pair_is_two_front_ends",
    "rtsgeom.paths.table.xǁPathsǁselect__mutmut_25": "test_a_selection_of_paths_keeps_every_column",
    "rtsgeom.identify.identification.x_identify__mutmut_73":
        "test_identifying_a_nominal_radar_finds_no_antenna_errors",
    "rtsgeom.identify.joint.xǁJointModelǁnominal__mutmut_3":
        "test_identifying_a_nominal_radar_finds_no_antenna_errors",
    "rtsgeom.analysis.nearfield.x__check_radii__mutmut_31":
        "test_bad_arc_radii_are_listed_four_at_most",
    # seed 23 (after its report; each confirmed with MUTANT_UNDER_TEST in the mutated copy)
    "rtsgeom.analysis.object_design.xǁObjectDesignResultǁplot__mutmut_157":
        "test_the_figure_draws_each_designs_share_centroid_and_targets_kept",
    "rtsgeom.analysis.playback.result.xǁPlaybackResultǁplot__mutmut_28":
        "test_the_figure_draws_the_set_and_detected_azimuths_of_each_mode",
    "rtsgeom.analysis.tolerance.cell.x_build_cell__mutmut_78":
        "test_a_cell_holding_no_set_direction_is_refused",
    "rtsgeom.analysis.tolerance.montecarlo.xǁToleranceResultǁyield___mutmut_4":
        "test_a_study_of_no_draws_has_no_yield_and_warns_of_nothing",
    "rtsgeom.analysis.tolerance.verify.xǁVerifyResultǁworst_difference_deg__mutmut_5":
        "test_verified_differences_per_draw_an_undetected_draw_infinite",
    # seed 31 (after its report; confirmed with MUTANT_UNDER_TEST, not re-run by the driver)
    "rtsgeom.analysis.tolerance.pair.x__set_beams__mutmut_15":
        "test_the_beams_derivatives_are_the_beams_slopes_in_u",
    "rtsgeom.pipeline.run.xǁRunResultǁ_summary__mutmut_35":
        "test_a_run_summary_lists_twelve_targets_and_counts_the_rest",
    "rtsgeom.analysis.linearity_study.xǁArcLinearityǁwrite__mutmut_27":
        "test_an_arc_writes_a_figure_per_pair_and_its_json",
    "rtsgeom.analysis.nearfield_terms.x_synthesis_worst_errors_deg__mutmut_63":
        "test_spans_that_do_not_overlap_have_no_synthesis_errors",
    "rtsgeom.identify.model.x__check_peak__mutmut_28":
        "test_a_sidecar_putting_the_probe_elsewhere_names_where_the_echo_is",
}

# a sample's mutant -> the same change under its name in today's code (the function moved to
# another module, or edits above it renumbered its mutants); --rerun-survivors runs that one.
# Found by comparing mutmut's diffs (the changed lines must be identical).
RENAMED: dict[str, str] = {
    "rtsgeom.calibration.pair.x_fir_effect__mutmut_5": "rtsgeom.calibration.fir.x_fir_effect__mutmut_5",
    "rtsgeom.calibration.pair.x_fir_effect__mutmut_134":
        "rtsgeom.calibration.fir.x_fir_effect__mutmut_108",
    "rtsgeom.analysis.ghosts.x_measure_ghosts__mutmut_189":
        "rtsgeom.analysis.ghosts.x_measure_ghosts__mutmut_151",
    "rtsgeom.calibration.pair.x_calibrate_pair__mutmut_207":
        "rtsgeom.calibration.pair.x_calibrate_pair__mutmut_215",
    "rtsgeom.calibration.pair.x_calibrate_pair__mutmut_245":
        "rtsgeom.calibration.pair.x_calibrate_pair__mutmut_267",
    "rtsgeom.pipeline.plan.x_plan_targets__mutmut_161": "rtsgeom.pipeline.plan.x_plan_targets__mutmut_178",
    "rtsgeom.calibration.sweep.x_fit_minimum__mutmut_80": "rtsgeom.calibration.sweep.x_fit_minimum__mutmut_74",
    "rtsgeom.identify.capture.x_read_capture__mutmut_78":
        "rtsgeom.identify.capture.x_read_capture__mutmut_113",
    "rtsgeom.radar.steering.xǁSteeringǁpeak__mutmut_69":
        "rtsgeom.radar.steering.xǁSteeringǁpeak__mutmut_87",
    "rtsgeom.radar.steering.xǁSteeringǁbuild__mutmut_16":
        "rtsgeom.radar.steering.xǁSteeringǁbuild__mutmut_39",
}

# survivors not killed and not shown equivalent: why (printed with their diff)
NOT_KILLED: dict[str, str] = {
    "rtsgeom.analysis.design.x_evaluate_design__mutmut_62":
        "the 'synthesis failed' branch needs ChannelPhasors.build to raise ValueError; no design "
        "tried reaches it (spacings 35-140 deg at 0.3 and 1 m: the composite's searched peak "
        "always brackets the set angle, the design returns a worst error of 26-132 deg "
        "instead). Unreachable in practice, not proven; counted as a survivor.",
    # seed 11: left without a test (reasons)
    "rtsgeom.analysis.coverage.x_coverage_designs__mutmut_45":
        "the setup-errors warning's text ('design ...'): the test that matches it "
        "(test_each_api_warning_points_at_the_callers_line) also checks the warning's line, "
        "which mutmut's trampolines move, so mutation runs leave it out.",
    "rtsgeom.analysis.coverage.xǁCoverageDesignǁplot__mutmut_55":
        "the coverage figure's contour floor (a plot's look, not a number); no figure test "
        "reads contour levels.",
    "rtsgeom.analysis.transfer.x__probe__mutmut_21":
        "the transfer study's 'front end not detected' message on a radar without "
        "[radar.channels] would end in an AttributeError; no fast test has an undetected "
        "front end in the transfer study. A real gap, left for time.",
    "rtsgeom.radar.estimators.x_uniform_cells__mutmut_14":
        "the uniform-grid check's tolerance 1e-8 m instead of 1e-6 x pitch (2e-9 m at 77 GHz): "
        "differs only for an array irregular by 2 to 10 nm, far below any antenna tolerance.",
    "rtsgeom.radar.phasors.x_bin_response__mutmut_95":
        "one word's case in a ValueError for a caller's misuse (taps with fast gains), not "
        "for user input; no test matches that text.",
    "rtsgeom.analysis.tolerance.study.xǁToleranceReportǁdraw_arrays__mutmut_16":
        "no fast test: tolerance_draws.npz is written by the CLI, whose tests run it in-process "
        "but carry 'cli' in their names and are left out of mutation runs.",
    "rtsgeom.synthesis.model.xǁChannelModelǁangles__mutmut_10":
        "no fast test calls ChannelModel.angles on a 1-D model; the clip's lower bound matters "
        "only for u < -1 (a rounding past -1).",
    # seed 23: left without a test (reason)
    "rtsgeom.calibration.beam.xǁBeamProbesǁ__init____mutmut_90":
        "an axis pair's boundary '<=' -> '<' at exactly sin(10 deg): differs only for a pair "
        "whose line is at 10 deg from an axis to the last bit, which a scene's geometry "
        "(front ends given in degrees, direction cosines computed) does not produce; "
        "practically equivalent, not proven, counted as a survivor.",
    # seed 31 (a second fresh sample): the first pass's survivors (none shown equivalent)
    "rtsgeom.analysis.kpi.sections.x_resolution_section__mutmut_49":
        "the datasheet's resolution step told its progress without its total: a TypeError for "
        "a caller that passes progress; no test ran the datasheet with progress.",
    "rtsgeom.analysis.nearfield_terms.x_synthesis_worst_errors_deg__mutmut_63":
        "a key's name in the branch of a pair whose measured and geometric spans do not "
        "overlap; no test has such a pair. Killed since by "
        "test_spans_that_do_not_overlap_have_no_synthesis_errors (run with MUTANT_UNDER_TEST in "
        "the mutated copy: fails there, passes unmutated)",
    "rtsgeom.analysis.tolerance.pair.x__set_beams__mutmut_15":
        "the beams' first derivative doubled: the Newton refinement of the set-points' peaks "
        "takes other steps; the tests' tolerances (the grid search, the chain) do not see the "
        "difference. Not shown equivalent. Killed since by "
        "test_the_beams_derivatives_are_the_beams_slopes_in_u (run with MUTANT_UNDER_TEST in the "
        "mutated copy: fails there, passes unmutated)",
    "rtsgeom.identify.model.x__check_peak__mutmut_28":
        "the range bin in the 'not where the capture's strongest echo is' message computed "
        "c / f_adc instead of c f_adc: the message's range is wrong; no test reads it. Killed "
        "since by test_a_sidecar_putting_the_probe_elsewhere_names_where_the_echo_is (run with "
        "MUTANT_UNDER_TEST in the mutated copy: fails there, passes unmutated)",
    "rtsgeom.pipeline.plan.x_target_namer__mutmut_12":
        "a budget-merged target's name loses '(merged target of N scatterers)'; no test reads "
        "that name.",
    "rtsgeom.pipeline.run.xǁRunResultǁ_summary__mutmut_35":
        "the run summary's '... N more targets' row at exactly MAX_SUMMARY_TARGETS targets "
        "(a boundary no test has). Killed since by "
        "test_a_run_summary_lists_twelve_targets_and_counts_the_rest (run with MUTANT_UNDER_TEST "
        "in the mutated copy: fails there, passes unmutated)",
    "rtsgeom.rts.fir.x__fir_rows__mutmut_99":
        "the FIR memo's branch for more settings than it holds (computed, not kept) with a "
        "wrong kernel phase; no test asks for that many settings at once.",
    "rtsgeom.synthesis.model.xǁChannelModelǁair_legs__mutmut_58":
        "a drawn front-end pitch ignored in the air legs (the scene's pitch kept): no test "
        "draws a pitch through ChannelModel.air_legs.",
    "rtsgeom.analysis.linearity_study.xǁArcLinearityǁwrite__mutmut_27":
        "no fast test writes an arc's linearity folder (linearity.json's name). Killed since by "
        "test_an_arc_writes_a_figure_per_pair_and_its_json (run with MUTANT_UNDER_TEST in the "
        "mutated copy: fails there, passes unmutated)",
    # seed 37 (a third fresh sample; no test written for it)
    "rtsgeom.analysis.coverage.xǁCoverageDesignǁ_columns__mutmut_15":
        "the coverage table's worst_uncalibrated_deg column renamed: no test reads that column "
        "of CoverageDesign.to_dataframe().",
    "rtsgeom.analysis.transfer.xǁTransferStudyǁ__call____mutmut_13":
        "the transfer study's refusal of a RuT that beamforms in 2-D, its plain words' case: "
        "no test has a 2-D RuT in the transfer study (the message was tried, not kept as a "
        "test).",
    "rtsgeom.calibration.fit.x_continuous_steps__mutmut_110":
        "the jump detector's threshold 2 -> 3 x JUMP_FACTOR: no test has a jump between the two "
        "(a heuristic's constant, not checked at its edge).",
    "rtsgeom.pipeline.run.x_summary__mutmut_48":
        "summary.json's radar.snr_db key renamed: no test reads that key.",
    "rtsgeom.radar.processing.xǁRangeDopplerǁrange_angle_to_xarray__mutmut_10":
        "the range-angle map's default angle grid from +60 instead of -60 deg: no test calls "
        "it without angles.",
    "rtsgeom.radar.steering.xǁSteeringǁ_search_smoothed_blocks__mutmut_190":
        "the smoothed search's parabolic refinement index clipped one short at the upper end: "
        "differs only for a peak at the zoom grid's last interior point; no test has one.",
    # seed 41 (a fourth fresh sample; no test written for it)
    "rtsgeom.analysis.design.xǁDesignGridǁplot__mutmut_47":
        "a word's case in the design map's title note ('hatched'); no test reads that note.",
    "rtsgeom.analysis.kpi.sections.x_ghosts_section__mutmut_70":
        "the datasheet's setup_echoes_note text; no test reads it.",
    "rtsgeom.analysis.kpi.sections.x_nearfield_section__mutmut_72":
        "the datasheet's near-field section loses its pairs (the key read under another name "
        "gives []); no test reads the section's pairs. A real gap.",
    "rtsgeom.analysis.playback.frames.xǁFramePlannerǁprogram__mutmut_19":
        "a drive's per-frame budget ignored (every frame's full programme instead of its "
        "budget's lead programme); no fast test plays a drive under a target budget through "
        "FramePlanner.program. A real gap.",
    "rtsgeom.calibration.fir.x_fir_sweep_phase__mutmut_46":
        "the continuous-delay branch of the FIR sweep's phase with channel J's base offset "
        "subtracted instead of added; no test's result tells them apart. Not analysed further "
        "(the session's time), not shown equivalent.",
    "rtsgeom.calibration.probes.x_probes_per_frame__mutmut_42":
        "'>' -> '>=' at the probes' last range exactly at the limit (a float boundary no "
        "test has).",
    "rtsgeom.identify.model.x_measure__mutmut_91":
        "the best range bin searched over 4 bins (-1..+2) instead of 3: differs only where the "
        "bin two above the model's has the most power, which no test's capture has.",
    "rtsgeom.pipeline.pair.x__closed_form_plan__mutmut_8":
        "the closed-form plan's model built without the calibrated offsets (None): the paper "
        "and array-factor ratios are closed forms of the geometry; the offsets (ps of delay) "
        "enter only the model's phase and gains used beside them, by less than the tests' "
        "tolerances, it seems. Not shown equivalent.",
    "rtsgeom.pipeline.plan.x_calibrate_pairs__mutmut_19":
        "the 'calibration file has no pair' message indexes the second missing pair: an "
        "IndexError instead of the SceneError where one pair is missing; no test loads a "
        "calibration file that lacks a pair the run needs. A real gap.",
    "rtsgeom.radar.processing.xǁRangeDopplerǁto_xarray__mutmut_27":
        "the range-Doppler array's long_name attribute text; no test reads it.",
    "rtsgeom.scene.objects.x_check_static_objects__mutmut_30":
        "one word's case in an object's 'azimuth in front of the RuT' refusal; no test has an "
        "object scatterer behind the RuT.",
    "rtsgeom.scene.scenario.x_check_scenario__mutmut_36":
        "the 'a drive starts at t_s = 0' refusal's text; no test has a drive starting later.",
}
