"""The browser tests' pages draw at most `FRAME_RATE` frames a second (`browser_page.py`),
and every callback asked for in one frame still runs in the same frame: Meshcat's drawing
and the front's answer to a batch share frames, and neither waits on the other.

Needs Debian's `chromium` and Playwright from PyPI; skipped where either is missing.
"""

from browser_page import FRAME_RATE, NEEDS_BROWSER, open_page

pytestmark = NEEDS_BROWSER

# Two loops of animation frames, as a Meshcat page has (its drawing, and the answer to the
# front's batches), counting for two seconds the frames each ran in.
COUNT_FRAMES = """() => new Promise(done => {
  const frames = [[], []], start = performance.now();
  function loop(which) {
    requestAnimationFrame(time => {
      frames[which].push(time);
      if (performance.now() - start < 2000) loop(which);
      else if (which === 1) done(frames);
    });
  }
  loop(0);
  loop(1);
})"""


def test_a_page_draws_at_most_frame_rate_frames_a_second_and_each_callback_runs():
    with open_page("data:text/html,<title>frames</title>") as page:
        drawing, answers = page.evaluate(COUNT_FRAMES)
    assert 2 * FRAME_RATE - 1 <= len(drawing) <= 2 * FRAME_RATE + 1, drawing
    assert set(answers) <= set(drawing) and len(answers) >= len(drawing) - 1
    gaps = [later - earlier for earlier, later in zip(drawing, drawing[1:])]
    assert min(gaps) >= 1000 / FRAME_RATE - 1, gaps
