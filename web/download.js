// Files leave the page as downloads: one helper for every button that saves something.

/** Saves `data` (a Blob, or text or bytes of MIME `type`) as a download named `name`. */
export function download(name, data, type = 'application/octet-stream') {
  const url = URL.createObjectURL(data instanceof Blob ? data : new Blob([data], { type }));
  const a = Object.assign(document.createElement('a'), { href: url, download: name });
  a.click();
  // Revoked once the browser has started the download.
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}
