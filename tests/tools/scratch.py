"""Imported by every tools test that makes temporary files or folders: tempfile's default
folder becomes one private folder of this test process, removed when it exits (a failing or
interrupted test too), so the tests leave nothing in the shared /tmp."""
import atexit
import shutil
import tempfile


FOLDER = tempfile.mkdtemp(prefix="boxes-tools-test-")
tempfile.tempdir = FOLDER
atexit.register(shutil.rmtree, FOLDER, True)
