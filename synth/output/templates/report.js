// Clicking a step of a trace shows that state (situation, E, Z, ORD, PROH) and marks
// its active steps on the Grafcet drawing. No network, no libraries.
(function () {
  "use strict";
  var walks = JSON.parse(document.getElementById("report-data").textContent);
  function esc(s) {
    return String(s).replace(/[&<>"']/g, function (c) {
      return {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;"}[c];
    });
  }
  function table(st) {
    var rows = [["Step", st.event], ["Sit", st.situation.join(", ")], ["E (true)", st.E.join(" ") || "-"],
                ["Z (true)", st.Z.join(" ") || "-"], ["ORD", st.ord.join(", ") || "-"], ["PROH", st.proh || "-"]];
    if (st.stored.length) rows.push(["stored", st.stored.join(", ")]);
    if (st.elapsed.length) rows.push(["elapsed", st.elapsed.join(", ")]);
    return "<table>" + rows.map(function (r) {
      return "<tr><th>" + esc(r[0]) + "</th><td class='mono'>" + esc(r[1]) + "</td></tr>";
    }).join("") + "</table>";
  }
  var fixes = JSON.parse(document.getElementById("report-fixes").textContent);
  function mark(problem, k, steps) {
    var fig = document.getElementById("grafcet");
    if (!fig) return;
    var active = {}, fix = {};
    steps.forEach(function (x) { active["step_" + x.replace(/^X/, "")] = true; });
    (fixes[problem] || []).forEach(function (x) { fix["step_" + x] = true; });
    fig.querySelectorAll("g.node").forEach(function (g) {
      var title = g.querySelector("title");
      var shape = g.querySelector("polygon, ellipse");
      if (!title || !shape || title.textContent.indexOf("step_") !== 0) return;
      shape.setAttribute("fill", active[title.textContent] ? "#f9d71c" : "#ffffff");
      g.querySelectorAll("polygon, ellipse").forEach(function (s) {
        s.setAttribute("stroke", fix[title.textContent] ? "#c0392b" : "black");
        s.setAttribute("stroke-width", fix[title.textContent] ? "4" : "1");
      });
    });
    var caption = document.getElementById("chart-shows");
    if (caption) caption.textContent = "Active steps (filled) of blocking " + problem.slice(1) + ", trace step " + k +
      " (" + walks[problem][k].event + ")" + ((fixes[problem] || []).length ? "; outlined in red: the step to fix." : ".");
  }
  function show(problem, k) {
    var st = walks[problem][k];
    document.getElementById("panel-" + problem).innerHTML = table(st);
    document.querySelectorAll("button[data-problem='" + problem + "']").forEach(function (b) {
      b.classList.toggle("current", Number(b.dataset.step) === k);
    });
    mark(problem, k, st.situation);
  }
  document.querySelectorAll(".trace button").forEach(function (b) {
    b.addEventListener("click", function () { show(b.dataset.problem, Number(b.dataset.step)); });
  });
  Object.keys(walks).reverse().forEach(function (problem) { show(problem, walks[problem].length - 1); });
})();
