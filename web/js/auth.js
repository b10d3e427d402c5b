// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * auth.js - the daemon's token in the page. `make run` prints the
 * dashboard's address with the token in the fragment (#token=...), which
 * the browser never sends to a server nor in a Referer. Here it is taken
 * from there into sessionStorage (this tab only, gone when the tab
 * closes), removed from the address bar and history, and handed to api.js,
 * which sends it on every request. Links to the API's files (the CSV and
 * JSON downloads) cannot carry a header: with a token their click fetches
 * the file with it and saves the answer.
 */

import * as api from './api.js';
import { report } from './ui.js';
import { saveBlob } from './plots.js';

const KEY = 'convsim.token';

/* The token in the fragment "#token=T[&...]" (null if none), and the
 * fragment without it. */
function fromFragment(hash) {
	const parts = hash.replace(/^#/, '').split('&').filter(Boolean);
	const at = parts.findIndex(p => p.startsWith('token='));
	if (at < 0) return { token: null, rest: hash };
	const token = decodeURIComponent(parts[at].slice(6));
	parts.splice(at, 1);
	return { token, rest: parts.length ? `#${parts.join('&')}` : '' };
}

function storage(fn) {
	try { return fn(window.sessionStorage); } catch { return null; } /* storage disabled */
}

async function download(e) {
	const a = e.target.closest?.('a[download]');
	const href = a?.getAttribute('href');
	if (!href || !href.startsWith(api.BASE) || !api.hasToken()) return;
	e.preventDefault();
	try {
		saveBlob(await api.fetchBlob(href), a.download || href.split('/').pop());
	} catch (err) {
		report(err, 'Download');
	}
}

/* Take the token (fragment first, else this tab's storage) before the page
 * makes its first request. */
export function initAuth() {
	const { token, rest } = fromFragment(location.hash);
	if (token !== null) {
		storage(s => s.setItem(KEY, token));
		history.replaceState(null, '', location.pathname + location.search + rest);
	}
	api.setToken(token ?? storage(s => s.getItem(KEY)) ?? '');
	document.addEventListener('click', download);
}
