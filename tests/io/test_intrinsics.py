"""Camera intrinsics files: every supported layout loads, bad files name the file and the field."""

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symfruit import Camera, FileFormatError, InputError, SymfruitError, SymfruitWarning
from symfruit.io import camera_from_dict, load_camera

LAYOUTS = {
    "plain.json": json.dumps({"fx": 615.0, "fy": 616.0, "cx": 321.0, "cy": 239.0, "width": 640, "height": 480}),
    "realsense.json": json.dumps(
        {
            "color": {
                "fx": 615.0,
                "fy": 616.0,
                "ppx": 321.0,
                "ppy": 239.0,
                "width": 640,
                "height": 480,
                "model": "Brown Conrady",
                "coeffs": [0, 0, 0, 0, 0],
            }
        }
    ),
    "open3d.json": json.dumps(
        {"width": 640, "height": 480, "intrinsic_matrix": [615.0, 0, 0, 0, 616.0, 0, 321.0, 239.0, 1.0]}
    ),
    "ros1.yaml": "header: {frame_id: camera_color_optical_frame}\nheight: 480\nwidth: 640\n"
    "distortion_model: plumb_bob\nD: [0, 0, 0, 0, 0]\n"
    "K: [615.0, 0.0, 321.0, 0.0, 616.0, 239.0, 0.0, 0.0, 1.0]\n",
    "ros2.yaml": "height: 480\nwidth: 640\nk: [615.0, 0.0, 321.0, 0.0, 616.0, 239.0, 0.0, 0.0, 1.0]\n",
    "calibration.yml": "image_width: 640\nimage_height: 480\ncamera_name: d435\ncamera_matrix:\n"
    "  rows: 3\n  cols: 3\n  data: [615.0, 0.0, 321.0, 0.0, 616.0, 239.0, 0.0, 0.0, 1.0]\n",
}


@pytest.mark.parametrize("name", LAYOUTS)
def test_intrinsics_layouts(tmp_path, name):
    path = tmp_path / name
    path.write_text(LAYOUTS[name])
    assert load_camera(path) == Camera(fx=615.0, fy=616.0, cx=321.0, cy=239.0, width=640, height=480)


@pytest.mark.parametrize(
    "text, message",
    [
        ('{"fx": 615, "fy": 615, "cx": 320, "width": 640, "height": 480}', "lack field 'cy' \\(or 'ppy'\\)"),
        ('{"fx": 0, "fy": 615, "cx": 320, "cy": 240, "width": 640, "height": 480}', "positive"),
        ('{"fx": 615, "fy": 615, "cx": 320, "cy": 240}', "width and height"),
        ('{"K": [1, 2, 3], "width": 640, "height": 480}', "9 numbers"),
        (
            '{"fx": 1' + "0" * 400 + ', "fy": 615, "cx": 320, "cy": 240, "width": 640, "height": 480}',
            r"'fx' must be a number, got 10{11}\.\.\. \(401 digits\)",
        ),  # JSON's whole number beyond float
        ('{"K": [1' + "0" * 400 + ', 0, 320, 0, 615, 240, 0, 0, 1], "width": 640, "height": 480}', "9 numbers"),
        (
            '{"fx": 615, "fy": 615, "cx": 320, "cy": 240, "width": ' + "9" * 400 + ', "height": 480}',
            r"camera width is 9{12}\.\.\. \(400 digits\) pixels; at most 16384 are supported$",
        ),  # before: all 400 digits printed
        ('{"foo": 1}', "not recognised"),
        ("[1, 2]", "mapping"),
        ("{not json", "not valid JSON"),
    ],
)
def test_bad_intrinsics_name_the_file_and_field(tmp_path, text, message):
    path = tmp_path / "cam.json"
    path.write_text(text)
    with pytest.raises(FileFormatError, match=rf"cam.json: .*{message}"):
        load_camera(path)


@settings()
@given(st.binary(max_size=2048), st.sampled_from([".json", ".yaml"]))
def test_readers_survive_random_bytes(tmp_path, data, suffix):
    path = tmp_path / f"fuzz{suffix}"
    path.write_bytes(data)
    try:
        load_camera(path)
    except SymfruitError:
        pass


def test_a_mapping_handed_to_the_api_is_checked_as_files_are():
    # camera_from_dict (symfruit.complete's camera=) took unknown keys: a misspelt 'ppy' read as missing 'cy'
    plain = {"fx": 615.0, "fy": 616.0, "ppx": 321.0, "ppy": 239.0, "width": 640, "height": 480}
    with pytest.raises(InputError, match=r"unknown key 'ppyy' .*; did you mean 'ppy'\?"):
        camera_from_dict({**{k: v for k, v in plain.items() if k != "ppy"}, "ppyy": 239.0})
    with pytest.raises(InputError, match=r"unknown key 'colour\.hieght' .*; did you mean 'height'\?"):
        camera_from_dict({"colour": {**plain, "hieght": 480}})
    with pytest.raises(InputError, match=r"unknown key 'other' .*; known keys: "):
        camera_from_dict({"intrinsics": plain, "other": 1})
    assert camera_from_dict({**plain, "depth_scale": 0.001, "model": "brown_conrady", "coeffs": [0] * 5}).cx == 321.0


def test_nested_layouts_and_wrong_extensions(tmp_path):
    plain = {"fx": 615.0, "fy": 616.0, "cx": 321.0, "cy": 239.0, "width": 640, "height": 480}
    expected = Camera(fx=615.0, fy=616.0, cx=321.0, cy=239.0, width=640, height=480)
    for key in ("intrinsics", "colour", "camera_info"):
        assert camera_from_dict({key: plain, "depth": {"fx": 1}}) == expected
    assert camera_from_dict({**plain, "width": 640.0}) == expected  # a whole float is a size
    path = tmp_path / "cam.txt"
    path.write_text(json.dumps(plain))
    with pytest.raises(FileFormatError, match=r"cam\.txt: intrinsics must be \.json, \.yaml or \.yml"):
        load_camera(path)
    with pytest.raises(FileFormatError, match="no such intrinsics file"):
        load_camera(tmp_path / "missing.json")
    (tmp_path / "bool.json").write_text(json.dumps({**plain, "fx": True}))
    with pytest.raises(FileFormatError, match="'fx' must be a number"):
        load_camera(tmp_path / "bool.json")


def test_intrinsics_files_that_would_expand_or_never_end_are_refused(tmp_path):
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text("a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
                    "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\nfx: 615\n")  # fmt: skip
    with pytest.raises(FileFormatError, match=r"bomb\.yaml: .*aliases"):
        load_camera(bomb)
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(FileFormatError, match=r"deep\.json: intrinsics file is nested too deeply"):
        load_camera(deep)
    zero = tmp_path / "zero.json"
    zero.symlink_to("/dev/zero")
    with pytest.raises(FileFormatError, match=r"zero\.json: intrinsics file is larger than"):
        load_camera(zero)


def test_a_sensor_of_100000_pixels_a_side_is_refused_naming_the_file(tmp_path):
    path = tmp_path / "cam.json"
    path.write_text('{"fx": 615, "fy": 615, "cx": 320, "cy": 240, "width": 100000, "height": 100000}')
    with pytest.raises(FileFormatError, match=r"cam\.json: camera width is 100000 pixels"):
        load_camera(path)


@pytest.mark.parametrize(
    "data, message",
    [
        ({"depth_scal": 0.0001}, r"unknown key 'depth_scal' .*did you mean 'depth_scale'\?"),
        ({"ppxx": 321.0}, r"unknown key 'ppxx' .*did you mean 'ppx'\?"),
        ({"serial": "123"}, r"unknown key 'serial' .*known keys: D, K, "),
        ({"colour": {"fx": 615.0, "fxx": 1.0}}, r"unknown key 'colour\.fxx' .*did you mean 'fx'\?"),
        ({"color": {"depth_scale": 0.0001}}, r"'depth_scale' under 'color' is not read: write it at the top level"),
    ],
)
def test_a_key_no_layout_has_is_refused_naming_the_file_the_key_and_the_closest(tmp_path, data, message):
    plain = {"fx": 615.0, "fy": 616.0, "cx": 321.0, "cy": 239.0, "width": 640, "height": 480}
    nest = next(iter(data.values())) if isinstance(next(iter(data.values())), dict) else None
    path = tmp_path / "cam.json"
    path.write_text(json.dumps({k: {**plain, **v} for k, v in data.items()} if nest is not None else {**plain, **data}))
    with pytest.raises(FileFormatError, match=rf"cam\.json: {message}"):
        load_camera(path)
    with pytest.raises(FileFormatError, match=r"cam\.json: unknown key 'ppxx' .*did you mean 'ppx'\?"):
        load_camera(_written(tmp_path / "cam.json", {k: v for k, v in plain.items() if k != "cx"} | {"ppxx": 1.0}))


def test_every_layout_key_and_the_depth_keys_beside_them_are_read(tmp_path):
    ros = {"header": {"frame_id": "c"}, "height": 480, "width": 640, "distortion_model": "plumb_bob", "D": [0] * 5,
           "K": [615.0, 0.0, 321.0, 0.0, 616.0, 239.0, 0.0, 0.0, 1.0], "R": [1, 0, 0, 0, 1, 0, 0, 0, 1],
           "P": [615.0, 0, 321.0, 0, 0, 616.0, 239.0, 0, 0, 0, 1, 0], "binning_x": 0, "binning_y": 0, "roi": {},
           "depth_scale": 0.001}  # fmt: skip
    nested = {"color": {"fx": 615.0, "fy": 616.0, "ppx": 321.0, "ppy": 239.0, "width": 640, "height": 480,
                        "model": "Brown Conrady", "coeffs": [0] * 5}, "depth": {}, "depth_units": "mm"}  # fmt: skip
    expected = Camera(fx=615.0, fy=616.0, cx=321.0, cy=239.0, width=640, height=480)
    assert load_camera(_written(tmp_path / "ros.json", ros)) == expected
    assert load_camera(_written(tmp_path / "rs.json", nested)) == expected


PLAIN = {"fx": 615.0, "fy": 616.0, "cx": 321.0, "cy": 239.0, "width": 640, "height": 480}


@pytest.mark.parametrize(
    "extra, key, largest",
    [
        ({"model": "Brown Conrady", "coeffs": [0.06, -0.1, 0.001, -0.0008, 0.02]}, "coeffs", "-0.1"),
        ({"distortion_model": "rational_polynomial", "D": [0.5, -2.7, 0, 0, 1.5, 0.4, -2.5, 1.4]}, "D", "-2.7"),
        ({"distortion_coefficients": {"rows": 1, "cols": 5, "data": [0, 0, 0, 0.003, 0]}}, "distortion_coefficients",
         "0.003"),
    ],
)  # fmt: skip
def test_non_zero_distortion_is_named_in_a_warning_not_ignored_in_silence(tmp_path, extra, key, largest):
    path = _written(tmp_path / "cam.json", PLAIN | extra)
    with pytest.warns(
        SymfruitWarning, match=rf"cam\.json: non-zero distortion coefficients '{key}' \(largest {largest}\)"
    ):
        assert load_camera(path) == Camera(**PLAIN)
    with pytest.warns(SymfruitWarning, match=rf"^intrinsics: non-zero distortion coefficients '{key}'"):
        camera_from_dict({"color": PLAIN | extra})


def test_zero_or_absent_distortion_warns_nothing_and_garbled_coefficients_are_refused(tmp_path):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for extra in ({}, {"coeffs": [0] * 5}, {"D": []}, {"d": [0.0] * 8}):
            assert camera_from_dict(PLAIN | extra) == Camera(**PLAIN)
    for bad in ([float("nan"), 0, 0, 0, 0], ["0.1"], [True], 0.1, [1e400]):
        with pytest.raises(InputError, match="intrinsics field 'coeffs' must hold at most 16 finite numbers"):
            camera_from_dict(PLAIN | {"coeffs": bad})
    path = tmp_path / "cam.json"
    path.write_text(json.dumps(PLAIN)[:-1] + ', "D": [NaN, 0, 0, 0, 0]}')
    with pytest.raises(FileFormatError, match=r"cam\.json: intrinsics field 'D' must hold at most 16 finite numbers"):
        load_camera(path)


def _written(path, data):
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("centre", [{"cx": 700.0}, {"cy": -3.0}, {"cy": 600.0}])
def test_a_principal_point_outside_the_image_is_named_in_a_warning(tmp_path, centre):
    import warnings

    path = _written(tmp_path / "cam.json", PLAIN | centre)
    with pytest.warns(SymfruitWarning, match=r"cam\.json: the principal point \(cx .*\) lies outside the 640x480 "
                      r"image: are these the intrinsics of this resolution"):  # fmt: skip
        assert load_camera(path) == Camera(**(PLAIN | centre))  # used as given (a cropped image's may be so)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the image's edges (pixel centres at whole numbers) are inside
        for cx, cy in ((-0.5, -0.5), (639.5, 479.5)):
            load_camera(_written(tmp_path / "edge.json", PLAIN | {"cx": cx, "cy": cy}))


@pytest.mark.parametrize(
    "data, message",
    [({"intrinsic_matrix": [615, 0, 320, 0, 615, 240, 0, 0, 1]}, r"'intrinsic_matrix' \[615, 0, 320, 0, 615, 240, 0, "
      r"0, 1\] is not a pinhole intrinsic matrix .* column-major, as Open3D writes it"),  # before: cx = cy = 0
     ({"K": [615, 0, 0, 0, 615, 0, 320, 240, 1]}, r"'K' \[615, 0, 0, 0, 615, 0, 320, 240, 1\] is not .* row-major"),
     ({"k": [615, 0, 320, 0, 615, 240, 0, 0, 2]}, r"'k' .* its entries below the diagonal must be 0 and the last 1"),
     ({"K": [615, 0, 320, 0, 615, 240, 0, 0, 1], "k": [1, 0, 3, 0, 1, 2, 0, 0, 1]},
      r"give the focal lengths twice, as 'K' and 'k': which one is meant"),  # before: K read, k left unsaid
     ({"fx": 615, "fy": 615, "cx": 320, "cy": 240, "K": [1, 0, 3, 0, 1, 2, 0, 0, 1]}, r"as 'K' and 'fx'"),
     ({"fx": 615, "fy": 615, "cx": 320, "ppx": 300, "cy": 240}, r"the principal point's x twice, as 'cx' and 'ppx'"),
     ({"fx": 615, "fy": 615, "cx": 320, "cy": 240, "image_height": 480}, r"the height twice, as 'height' and "
      r"'image_height'")],
)  # fmt: skip
def test_a_transposed_or_scaled_matrix_and_a_value_given_twice_are_refused(tmp_path, data, message):
    base = {"width": 640, "height": 480}
    with pytest.raises(InputError, match=message):
        camera_from_dict(base | data)
    with pytest.raises(FileFormatError, match=r"cam\.json: intrinsics "):
        load_camera(_written(tmp_path / "cam.json", base | data))
    right = {"K": [615, 0, 320, 0, 615, 240, 0, 0, 1]}, {"intrinsic_matrix": [615, 0, 0, 0, 615, 0, 320, 240, 1]}
    assert {camera_from_dict(base | r) for r in right} == {Camera(615, 615, 320, 240, 640, 480)}


def test_intrinsics_given_twice_under_two_nests_that_differ_are_refused_not_one_taken(tmp_path):
    colour = {"fx": 615, "fy": 615, "cx": 320, "cy": 240, "width": 640, "height": 480}
    depth = {"fx": 380, "fy": 380, "cx": 212, "cy": 120, "width": 424, "height": 240}
    path = tmp_path / "cam.json"
    path.write_text(json.dumps({"intrinsics": depth, "color": colour}))
    with pytest.raises(FileFormatError, match=r"cam\.json: intrinsics are given twice, under 'intrinsics' and "
                       r"'color', and they differ: which one is meant\? Keep one$"):  # fmt: skip
        load_camera(path)  # before: 'intrinsics' read, the colour camera's left unsaid
    path.write_text(json.dumps({"color": colour, "colour": colour, "depth": depth}))  # the same twice: no doubt
    assert load_camera(path).fx == 615


@pytest.mark.parametrize(
    "extra, error",
    [({"binning_x": 2}, r"cam\.json: intrinsics field 'binning_x' is 2: binned images are not read"),
     ({"binning_y": 4}, r"field 'binning_y' is 4"),
     ({"roi": {"x_offset": 100, "y_offset": 0, "width": 320, "height": 240, "do_rectify": False}},
      r"field 'roi' is x_offset 100, y_offset 0, 320x240: a region of interest is not applied"),
     ({"roi": {"x_offset": 0, "y_offset": 0, "width": 320, "height": 240}}, r"field 'roi' is x_offset 0"),
     ({"binning_x": 2.5}, r"field 'binning_x' must be a whole number, got 2\.5"),
     ({"binning_x": 1e300}, r"field 'binning_x' must be a whole number, got 1e\+300"),
     ({"roi": [0, 0]}, r"field 'roi' must be a mapping"),
     ({"roi": {"x_offset": -1}}, r"field 'roi' must hold whole numbers")],
)  # fmt: skip
def test_binning_and_a_region_of_interest_are_refused_not_ignored(tmp_path, extra, error):
    """K of a binned or cropped CameraInfo is the full sensor's: read as the image's, every point was misplaced."""
    base = {"K": [600, 0, 320, 0, 600, 240, 0, 0, 1], "width": 640, "height": 480}
    path = tmp_path / "cam.json"
    path.write_text(json.dumps({**base, **extra}))
    with pytest.raises(FileFormatError, match=error):
        load_camera(path)
    none = {"binning_x": 0, "binning_y": 1, "roi": {"x_offset": 0, "y_offset": 0, "width": 0, "height": 0}}
    path.write_text(json.dumps({**base, **none}))  # ROS's "no binning, no roi"; so is the whole image's roi
    assert load_camera(path) == Camera(fx=600, fy=600, cx=320, cy=240, width=640, height=480)
    path.write_text(json.dumps({**base, "roi": {"x_offset": 0, "y_offset": 0, "width": 640, "height": 480}}))
    assert load_camera(path).width == 640


def test_a_key_no_layout_has_and_none_is_close_to_lists_the_near_ones_in_one_short_line(tmp_path):
    """Stop 48 (robust48): every key of every layout was listed (33 names, a line of 445 characters naming the
    file) for a key near none of them (a camera's ``serial`` or ``model`` written beside its intrinsics)."""
    path = _written(tmp_path / "cam.json", {"fx": 615.0, "fy": 616.0, "cx": 321.0, "cy": 239.0, "width": 640,
                                            "height": 480, "serial": "123"})  # fmt: skip
    from symfruit.io.intrinsics import DEPTH_KEYS, LAYOUT_KEYS

    with pytest.raises(FileFormatError) as info:
        load_camera(path)
    rest = len(LAYOUT_KEYS | DEPTH_KEYS) - 6
    assert str(info.value) == (f"{path}: unknown key 'serial' (not a key of any intrinsics layout symfruit reads); "
                               f"known keys: D, K, P, R, binning_x, binning_y and {rest} more (README's table of "
                               "inputs, row 'intrinsics', lists the layouts)")  # fmt: skip


def test_an_intrinsics_file_of_a_fisheye_model_is_warned_about_with_coefficients_all_zero(tmp_path):
    """Stop 48 (robust48): ``distortion_model: equidistant`` with ``D`` all 0 was read as pinhole in silence."""
    ros = {"height": 480, "width": 640, "distortion_model": "equidistant", "D": [0.0] * 4,
           "K": [615.0, 0, 320, 0, 615, 240, 0, 0, 1]}  # fmt: skip
    path = _written(tmp_path / "cam.json", ros)
    with pytest.warns(SymfruitWarning, match=r"cam\.json: distortion model 'equidistant' is a fisheye lens"):
        assert load_camera(path).fx == 615.0
