"""From projector coordinates to 3-D, one concept a module; the rig's kind (a camera and a
projector, or two cameras) is a parameter, not a module of its own.

============================  =================================================================
module                        what it holds
============================  =================================================================
``board.py``                  ``Board`` (chessboard, circle grids; ``detect``), ``parse_board``
                              (the one ``--board`` description parser), ``is_board_text``
``calibration.py``            the rigs and their one file: ``Device``, ``Uncertainty`` (its
                              devices named after the kind), ``Calibration`` (camera and
                              projector), ``StereoCalibration`` and ``ProjectorPose`` (two
                              cameras), ``load_calibration`` (either kind, as the file's
                              ``"kind"`` says), ``save_calibration``, ``check_pair``,
                              ``on_the_left``, ``right_centre``, ``short_baseline``,
                              ``is_stereo_file``; ``load_stereo_calibration`` and
                              ``save_stereo_calibration``: old names
``calibrate.py``              a rig from views of a board: ``calibrate_points`` (any two
                              devices), ``uncertainty``, ``calibrate_views``,
                              ``calibrate_poses`` (camera + projector),
                              ``calibrate_stereo_images`` (two cameras), ``check_min_poses``
``corners.py``                board features into the projector: ``PoseCapture``,
                              ``BoardView``, ``board_view``, ``feature_spacing``,
                              ``local_homography``, ``sample_local``
``opencv.py``                 OpenCV FileStorage files: ``read_filestorage``,
                              ``read_opencv_calibration``, ``read_opencv_stereo``
``projection_matrices.py``    ``P = K [R | t]`` files: ``read_matrix``, ``decompose``,
                              ``rig_from_matrices``, ``import_matrices``
``triangulate.py``            camera + projector to points: ``reconstruct``, ``triangulate``,
                              ``triangulate_axes``, ``baseline_orientation``, ``check_fit``,
                              ``check_depth_range``, ``Reconstruction``
``height.py``                 the reference-plane height model: ``HeightModel``
``stereo.py`` (+ ``_jit``)    two cameras: ``stereo``, ``reconstruct_stereo``, ``readings``,
                              ``decode_options``, ``rectify``, ``Rectification``,
                              ``StereoResult``; its twin: ``remap_valid``,
                              ``resample_wrapped``, ``rectified_positions``, ``grid_depth``,
                              ``depth_counts``, ``pick_finite``, ``grid_points``,
                              ``cloud_points``
``stereo_match.py``           the row search between them: ``match``, ``Matched``; its twin
                              ``stereo_match_jit.py``: ``drop_kinks``, ``line_coefficients``,
                              ``smooth_runs``, ``match_pair``, ``supported``, ``count_status``
``stereo_checks.py``          do the two cameras' inputs fit each other: ``same_captures``,
                              ``other_axis_share``, ``other_readings``, ``check_matches``,
                              ``projector_misfits``
``unwrap.py`` (+ ``_jit``)    stereo phase unwrapping of one period: ``stereo_unwrap``,
                              ``unwrap_stereo``, ``absolute_phase``, ``wrapped_of``,
                              ``rectified_phase``, ``cross_checked``, ``ghost_spacing``,
                              ``check_range``, ``is_single_period``, ``Unwrapped``; its twin:
                              ``unwrap_rows``
============================  =================================================================

``stereo_calibration.py``, ``stereo_calibrate.py`` and ``stereo_opencv.py`` are the old
homes of the two-camera names, kept for one release (they only import them).
"""
