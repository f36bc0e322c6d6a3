#!/usr/bin/python3
"""The printable mock exam in headless Chromium: the sheet and its key laid out on an A4 page
(no part wider than the page, no answer box or code block cut, every part and answer line
there), printed to PDF on a few pages; with --screenshots, a PNG of each page's top for a person to
look at.

usage: exam_sheet_test.py EXAM_PROGRAM WORK_DIR [--screenshots]
Exit 0 when both pages pass, 1 when one fails, 77 (ctest's skip) without Chromium."""
import html as html_lib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

SKIP = 77

# Run in the page after it is laid out at the width of an A4 page: what does not fit.
LAYOUT_CHECK = """
<script>
(function () {
  const problems = [];
  const page = document.documentElement.clientWidth;
  if (document.documentElement.scrollWidth > page + 1)
    problems.push("the page scrolls sideways: " + document.documentElement.scrollWidth + " > " + page);
  for (const el of document.querySelectorAll("body *")) {
    const r = el.getBoundingClientRect();
    if (r.width === 0 && r.height === 0) continue;
    if (r.right > page + 1) problems.push("<" + el.tagName.toLowerCase() + "> '" +
      (el.textContent || "").trim().slice(0, 40) + "' leaves the page");
    if (["PRE", "P", "SPAN"].includes(el.tagName) && el.scrollWidth > el.clientWidth + 1 &&
        getComputedStyle(el).overflowX !== "visible")
      problems.push("<" + el.tagName.toLowerCase() + "> '" + (el.textContent || "").trim().slice(0, 40) + "' is cut");
  }
  const emptyAnswers = [...document.querySelectorAll(".answer")].filter(a => !a.textContent.trim()).length;
  const result = {
    problems: problems.slice(0, 20),
    parts: document.querySelectorAll(".part").length,
    lines: document.querySelectorAll(".line").length,
    boxes: document.querySelectorAll(".line .box").length,
    answers: document.querySelectorAll(".line .answer").length,
    emptyAnswers,
    solutions: document.querySelectorAll(".solution").length,
    questions: document.querySelectorAll("h2").length,
  };
  const out = document.createElement("pre");
  out.id = "layout-result";
  out.textContent = JSON.stringify(result);
  document.body.appendChild(out);
})();
</script>
"""


def chromium():
    for path in (os.environ.get("CHROME_PATH"), "/usr/bin/chromium", "/usr/bin/chromium-browser"):
        if path and os.access(path, os.X_OK):
            return path
    return None


def browser(binary, profile, *args):
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
             "--no-first-run", "--user-data-dir=" + profile, "--hide-scrollbars"]
    return subprocess.run([binary, *flags, *args], capture_output=True, text=True, timeout=120)


def main():
    program, work = sys.argv[1], sys.argv[2]
    screenshots = "--screenshots" in sys.argv[3:]
    binary = chromium()
    if not binary:
        print("SKIP: no Chromium (the Debian package chromium)")
        return SKIP
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    run = subprocess.run([program, "--mock", "--seed", "1", "--sheet", work], capture_output=True,
                         text=True, timeout=300)
    print(run.stdout + run.stderr, end="")
    if run.returncode != 0:
        print("FAIL: the program could not write the sheet")
        return 1
    with open(os.path.join(work, "mock-1-answers.txt"), encoding="utf-8") as f:
        answer_lines = sum(1 for line in f if line.strip() and not line.startswith("#"))
    failures = []
    for name, key in (("mock-1", False), ("mock-1-key", True)):
        html = os.path.join(work, name + ".html")
        checked = os.path.join(work, name + "-checked.html")
        with open(html, encoding="utf-8") as f:
            text = f.read()
        with open(checked, "w", encoding="utf-8") as f:
            f.write(text.replace("</body>", LAYOUT_CHECK + "</body>"))
        profile = tempfile.mkdtemp(prefix="exam-sheet-chromium-")
        try:
            # 794 CSS pixels: an A4 page's width at 96 dpi.
            dom = browser(binary, profile, "--window-size=794,1123", "--dump-dom",
                          "file://" + os.path.abspath(checked))
            shot = None
            if screenshots:
                shot = browser(binary, profile, "--window-size=794,1123",
                               "--screenshot=" + os.path.join(work, name + ".png"),
                               "file://" + os.path.abspath(html))
        finally:
            shutil.rmtree(profile, ignore_errors=True)
        m = re.search(r'<pre id="layout-result">(.*?)</pre>', dom.stdout, re.S)
        if not m:
            failures.append(f"{name}: Chromium ran no layout check ({dom.stderr.strip()[:200]})")
            continue
        result = json.loads(html_lib.unescape(m.group(1)))
        print(f"{name}: {json.dumps(result)}")
        for p in result["problems"]:
            failures.append(f"{name}: {p}")
        if result["questions"] != 4 or result["parts"] != 18:
            failures.append(f"{name}: {result['questions']} questions and {result['parts']} parts, want 4 and 18")
        if result["lines"] != answer_lines:
            failures.append(f"{name}: {result['lines']} answer lines, the answer file has {answer_lines}")
        if key and (result["answers"] != answer_lines or result["emptyAnswers"] or result["solutions"] != 18):
            failures.append(f"{name}: the key shows {result['answers']} answers ({result['emptyAnswers']} empty) and {result['solutions']} solutions")
        if not key and (result["boxes"] != answer_lines or result["answers"]):
            failures.append(f"{name}: the sheet shows {result['boxes']} answer boxes and {result['answers']} answers")
        if shot and (shot.returncode != 0 or not os.path.exists(os.path.join(work, name + ".png"))):
            failures.append(f"{name}: no screenshot")
        pdf = os.path.join(work, name + ".pdf")
        if not os.path.exists(pdf):
            failures.append(f"{name}: no PDF")
            continue
        with open(pdf, "rb") as f:
            data = f.read()
        pages = len(re.findall(rb"/Type\s*/Page[^s]", data))
        print(f"{name}.pdf: {pages} A4 pages, {len(data)} bytes")
        if not data.startswith(b"%PDF") or not 2 <= pages <= (14 if key else 8):
            failures.append(f"{name}.pdf: {pages} pages")
    for f in failures:
        print("FAIL " + f)
    if screenshots:
        print(f"screenshots: {work}/mock-1.png, {work}/mock-1-key.png")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
