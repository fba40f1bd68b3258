// The login form: POST /login, then the page asked for (or the overview).
document.getElementById("login-form").addEventListener("submit", async (ev) => {
  ev.preventDefault();
  const r = await fetch("/login", {method: "POST", headers: {"Content-Type": "application/json"},
    body: JSON.stringify({user: document.getElementById("user").value,
                          password: document.getElementById("password").value})});
  if (r.ok) {
    const next = new URLSearchParams(location.search).get("next") || "/overview";
    location.href = next.startsWith("/") && !next.startsWith("//") ? next : "/overview";
  } else {
    document.getElementById("login-error").textContent = (await r.json()).error;
  }
});
document.getElementById("login-button").disabled = false;
