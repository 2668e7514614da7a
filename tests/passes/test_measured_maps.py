"""A comparator file names the axis it measures and the one its transverse gauge reads: without them
there is nothing to compensate, and the user is told so at the file's instrument line."""

from pathlib import Path

import pytest

from ncpp.errors import NcppError
from ncpp.passes.measured import map_from_file

SAMPLE = Path(__file__).resolve().parents[2] / "samples" / "thesis" / "comparator_X_predicted_from_laser.csv"


@pytest.mark.parametrize("key", ["axis", "transverse"])
def test_comparator_without_axis_metadata_is_refused(tmp_path, key):
    lines = [line for line in SAMPLE.read_text().splitlines() if not line.startswith(f"# {key}:")]
    path = tmp_path / "c.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(NcppError, match=f"# {key}: X"):
        map_from_file(str(path))


def test_comparator_sample_maps_its_axis():
    m = map_from_file(str(SAMPLE))
    assert m.axis == 0 and m.deviation_mm.shape[1] == 3 and m.deviation_mm[:, 1].any()
